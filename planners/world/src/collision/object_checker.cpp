#include "pullout/collision/object_checker.hpp"

#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/convex.h>
#include <fcl/narrowphase/collision_object.h>
#include <fcl/narrowphase/distance.h>
#include <algorithm>
#include <cmath>

namespace pullout {

namespace {

// Height of the prisms FCL works with; the problem is planar, any positive value gives the same
// planar distances because every prism spans the same z range.
constexpr double kPrismHeight = 1.0;

double cross(const Vec2& o, const Vec2& a, const Vec2& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

// Andrew's monotone chain; counter-clockwise, no collinear points.
Polygon convex_hull(Polygon pts) {
  std::sort(pts.begin(), pts.end(),
            [](const Vec2& a, const Vec2& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); });
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
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

struct PreparedObstacle {
  std::int64_t id;
  Vec2 centre;
  double radius;  // bounding circle around centre
  std::shared_ptr<fcl::Convexd> shape;
  std::unique_ptr<fcl::CollisionObjectd> object;
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
    Polygon hull = convex_hull(std::move(o.polygon));
    if (hull.size() < 3) continue;  // degenerate: validation rejects such objects earlier
    Vec2 centre = Vec2::Zero();
    for (const Vec2& p : hull) centre += p;
    centre /= static_cast<double>(hull.size());
    double radius = 0.0;
    for (const Vec2& p : hull) radius = std::max(radius, (p - centre).norm());
    PreparedObstacle prepared{o.id, centre, radius, make_prism(hull, centre), nullptr};
    prepared.object = std::make_unique<fcl::CollisionObjectd>(prepared.shape, planar_transform(centre, 0.0));
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
  for (const PreparedObstacle& o : impl_->obstacles) {
    if (!keep(o.centre)) continue;
    // Lower bound of the distance from the two bounding circles.
    const double lower = (o.centre - box_centre).norm() - o.radius - impl_->box_radius;
    if (lower >= horizon || lower >= best.distance) continue;
    if (!vehicle) vehicle.emplace(impl_->box, planar_transform(box_centre, pose.yaw));
    fcl::DistanceResultd result;
    fcl::distance(&*vehicle, o.object.get(), request, result);
    // Without signed distance FCL reports a negative value for overlapping shapes.
    const double d = std::max(result.min_distance, 0.0);
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
