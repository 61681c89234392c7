#include "pullout/collision/object_checker.hpp"

#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/convex.h>
#include <fcl/narrowphase/collision_object.h>
#include <fcl/narrowphase/distance.h>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>

#include "pullout/geometry/polygon.hpp"

namespace pullout {

namespace {

// Height of the prisms FCL works with; the problem is planar, any positive value gives the same
// planar distances because every prism spans the same z range.
constexpr double kPrismHeight = 1.0;

double cross(const Vec2& o, const Vec2& a, const Vec2& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

// The points sorted by x, then y, each once.
Polygon distinct_points(Polygon pts) {
  std::sort(pts.begin(), pts.end(),
            [](const Vec2& a, const Vec2& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); });
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  return pts;
}

// Andrew's monotone chain over distinct_points; counter-clockwise, no collinear points.
Polygon convex_hull(const Polygon& pts) {
  if (pts.size() < 3) return pts;
  Polygon hull(2 * pts.size());
  std::size_t k = 0;
  for (const Vec2& p : pts) {
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], p) <= 0) --k;
    hull[k++] = p;
  }
  for (std::size_t i = pts.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && cross(hull[k - 2], hull[k - 1], pts[i]) <= 0) --k;
    hull[k++] = pts[i];
  }
  hull.resize(k - 1);
  return hull;
}

// Whether the closed polygon (no repeated consecutive points, no collinear ones) is simple: no
// two edges meet except neighbours at their common vertex.
bool simple(const Polygon& pts) {
  const std::size_t n = pts.size();
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // neighbours through the closing edge
      if (segments_intersect(pts[i], pts[(i + 1) % n], pts[j], pts[(j + 1) % n])) return false;
    }
  }
  return true;
}

// The triangles whose union is the simple polygon `pts` (ear clipping; collinear points and
// repeats dropped), or none when its edges cross (which side is inside is then a guess) or
// rounding leaves no ear: the caller keeps the convex hull then, which covers every reading.
std::vector<std::array<Vec2, 3>> triangulate(Polygon pts) {
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  while (pts.size() > 1 && pts.front() == pts.back()) pts.pop_back();
  for (bool removed = true; removed && pts.size() >= 3;) {
    removed = false;
    for (std::size_t i = 0; i < pts.size() && pts.size() >= 3; ++i) {
      const std::size_t n = pts.size();
      if (cross(pts[(i + n - 1) % n], pts[i], pts[(i + 1) % n]) == 0.0) {
        pts.erase(pts.begin() + static_cast<std::ptrdiff_t>(i));
        removed = true;
      }
    }
  }
  if (pts.size() < 3 || !simple(pts)) return {};
  if (signed_area(pts) < 0.0) std::reverse(pts.begin(), pts.end());
  // A convex vertex whose triangle holds no other vertex (on its edges included) is an ear, cut
  // off; a simple polygon of 4 or more vertices always has two.
  std::vector<std::array<Vec2, 3>> out;
  while (pts.size() > 3) {
    const std::size_t n = pts.size();
    bool cut = false;
    for (std::size_t i = 0; i < n && !cut; ++i) {
      const Vec2& a = pts[(i + n - 1) % n];
      const Vec2& b = pts[i];
      const Vec2& c = pts[(i + 1) % n];
      if (cross(a, b, c) <= 0.0) continue;  // reflex (or flat): not an ear
      bool empty = true;
      for (std::size_t k = 0; k < n && empty; ++k) {
        if (k == i || k == (i + n - 1) % n || k == (i + 1) % n) continue;
        const Vec2& p = pts[k];
        empty = !(cross(a, b, p) >= 0.0 && cross(b, c, p) >= 0.0 && cross(c, a, p) >= 0.0);
      }
      if (!empty) continue;
      out.push_back({a, b, c});
      pts.erase(pts.begin() + static_cast<std::ptrdiff_t>(i));
      cut = true;
    }
    if (!cut) return {};
  }
  if (cross(pts[0], pts[1], pts[2]) > 0.0) out.push_back({pts[0], pts[1], pts[2]});
  return out;
}

// A vertical prism over a convex polygon (counter-clockwise) centred at its centroid, so that the
// object transform carries the position.
std::shared_ptr<fcl::Convexd> make_prism(const Polygon& hull, const Vec2& centre) {
  const int n = static_cast<int>(hull.size());
  auto vertices = std::make_shared<std::vector<fcl::Vector3d>>();
  vertices->reserve(2 * hull.size());
  for (const Vec2& p : hull) vertices->emplace_back(p.x() - centre.x(), p.y() - centre.y(), -kPrismHeight / 2);
  for (const Vec2& p : hull) vertices->emplace_back(p.x() - centre.x(), p.y() - centre.y(), kPrismHeight / 2);
  // Faces: count followed by vertex indices, counter-clockwise seen from outside.
  auto faces = std::make_shared<std::vector<int>>();
  faces->push_back(n);  // bottom, seen from below
  for (int i = n - 1; i >= 0; --i) faces->push_back(i);
  faces->push_back(n);  // top
  for (int i = 0; i < n; ++i) faces->push_back(n + i);
  for (int i = 0; i < n; ++i) {  // sides
    const int j = (i + 1) % n;
    faces->insert(faces->end(), {4, i, j, n + j, n + i});
  }
  return std::make_shared<fcl::Convexd>(vertices, n + 2, faces);
}

fcl::Transform3d planar_transform(const Vec2& position, double yaw) {
  fcl::Transform3d tf = fcl::Transform3d::Identity();
  tf.translation() = fcl::Vector3d(position.x(), position.y(), 0.0);
  tf.linear() = Eigen::AngleAxisd(yaw, fcl::Vector3d::UnitZ()).toRotationMatrix();
  return tf;
}

// A convex shape FCL measures against, with its bounding circle.
struct Piece {
  Vec2 centre;
  double radius{0.0};
  std::shared_ptr<fcl::Convexd> shape;
  std::unique_ptr<fcl::CollisionObjectd> object;
};

template <typename Points>
void bound(const Points& points, Piece& piece) {
  piece.centre = Vec2::Zero();
  for (const Vec2& p : points) piece.centre += p;
  piece.centre /= static_cast<double>(points.size());
  for (const Vec2& p : points) piece.radius = std::max(piece.radius, (p - piece.centre).norm());
}

// A convex polygon (counter-clockwise) as a prism spanning the vehicle box's height. (FCL 0.7
// has no distance between a box and a flat triangle: TriangleP answers "not supported".)
Piece prism_piece(const Polygon& convex) {
  Piece piece;
  bound(convex, piece);
  piece.shape = make_prism(convex, piece.centre);
  piece.object = std::make_unique<fcl::CollisionObjectd>(piece.shape, planar_transform(piece.centre, 0.0));
  return piece;
}

// The convex pieces of a non-convex object, made when a query first comes near it (most objects
// of a large request never do): the decomposition and its FCL shapes cost far more than the hull.
struct LazyPieces {
  std::once_flag once;
  Polygon polygon;
  std::vector<Piece> pieces;
};

struct PreparedObstacle {
  std::int64_t id;
  Piece hull;                          // the object's convex hull (its centre: clearance_ahead's)
  std::unique_ptr<LazyPieces> pieces;  // null for a convex object (the hull is the object)
};

}  // namespace

struct ObjectChecker::Impl {
  Footprint footprint;
  Vec2 box_offset;  // centre of the footprint box in base_link
  double box_radius;
  std::shared_ptr<fcl::Boxd> box;
  std::vector<PreparedObstacle> obstacles;
};

ObjectChecker::ObjectChecker(const Footprint& vehicle, std::vector<Obstacle> obstacles)
    : impl_(std::make_unique<Impl>()) {
  impl_->footprint = vehicle;
  impl_->box_offset = Vec2((vehicle.front - vehicle.rear) / 2.0, (vehicle.left - vehicle.right) / 2.0);
  impl_->box_radius = 0.5 * std::hypot(vehicle.length(), vehicle.width());
  impl_->box = std::make_shared<fcl::Boxd>(vehicle.length(), vehicle.width(), kPrismHeight);
  for (Obstacle& o : obstacles) {
    const Polygon distinct = distinct_points(o.polygon);
    const Polygon hull = convex_hull(distinct);
    if (hull.size() < 3) continue;  // degenerate: validation rejects such objects earlier
    PreparedObstacle prepared{o.id, prism_piece(hull), nullptr};
    // Convex (its hull has all of its distinct points): the hull is the object.
    if (distinct.size() != hull.size()) {
      prepared.pieces = std::make_unique<LazyPieces>();
      prepared.pieces->polygon = std::move(o.polygon);
    }
    impl_->obstacles.push_back(std::move(prepared));
  }
}

ObjectChecker::~ObjectChecker() = default;
ObjectChecker::ObjectChecker(ObjectChecker&&) noexcept = default;
ObjectChecker& ObjectChecker::operator=(ObjectChecker&&) noexcept = default;

const Footprint& ObjectChecker::footprint() const { return impl_->footprint; }

ObjectChecker::Clearance ObjectChecker::clearance(const Pose2& pose, double horizon) const {
  return clearance_if(pose, horizon, [](const Vec2&) { return true; });
}

ObjectChecker::Clearance ObjectChecker::clearance_ahead(const Pose2& pose, double horizon) const {
  const double front = impl_->footprint.front;
  return clearance_if(pose, horizon, [&pose, front](const Vec2& centre) { return to_local(pose, centre).x() > front; });
}

template <typename Filter>
ObjectChecker::Clearance ObjectChecker::clearance_if(const Pose2& pose, double horizon, Filter&& keep) const {
  Clearance best;
  if (impl_->obstacles.empty()) return best;
  const Vec2 box_centre = to_global(pose, impl_->box_offset);
  std::optional<fcl::CollisionObjectd> vehicle;
  fcl::DistanceRequestd request;
  request.enable_nearest_points = false;
  // FCL 0.7's libccd distance for box-convex pairs is off by up to 0.4 m (tests/planners/
  // test_object_checker.cpp catches it); its own GJK implementation is exact to 1e-6 m.
  request.gjk_solver_type = fcl::GST_INDEP;
  // The distance to `piece` when it may be below both the horizon and the best so far (the
  // bounding circles first), else +inf. Without signed distance FCL reports a negative value for
  // overlapping shapes.
  const auto measure = [&](const Piece& piece) {
    const double lower = (piece.centre - box_centre).norm() - piece.radius - impl_->box_radius;
    if (lower >= horizon || lower >= best.distance) return std::numeric_limits<double>::infinity();
    if (!vehicle) vehicle.emplace(impl_->box, planar_transform(box_centre, pose.yaw));
    fcl::DistanceResultd result;
    fcl::distance(&*vehicle, piece.object.get(), request, result);
    return std::max(result.min_distance, 0.0);
  };
  for (const PreparedObstacle& o : impl_->obstacles) {
    if (!keep(o.hull.centre)) continue;
    double d = measure(o.hull);
    // A non-convex object is no nearer than its hull: its pieces only where the hull is near.
    if (o.pieces != nullptr && d < horizon && d < best.distance) {
      LazyPieces& lazy = *o.pieces;
      std::call_once(lazy.once, [&lazy] {
        for (const auto& t : triangulate(lazy.polygon)) lazy.pieces.push_back(prism_piece({t[0], t[1], t[2]}));
      });
      if (!lazy.pieces.empty()) {  // (none: edges that cross, the hull stands for it)
        d = std::numeric_limits<double>::infinity();
        for (const Piece& piece : lazy.pieces) d = std::min(d, measure(piece));
      }
    }
    if (d < best.distance && d < horizon) {
      best.distance = d;
      best.obstacle_id = o.id;
    }
  }
  return best;
}

std::optional<ObjectChecker::Hit> ObjectChecker::first_hit(const std::vector<Pose2>& poses, double margin) const {
  if (impl_->obstacles.empty()) return std::nullopt;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const Clearance c = clearance(poses[i], margin);
    if (c.distance < margin) return Hit{i, c.obstacle_id, c.distance};
  }
  return std::nullopt;
}

}  // namespace pullout
