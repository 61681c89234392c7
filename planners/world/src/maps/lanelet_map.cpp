#include "pullout/maps/lanelet_map.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

#include "pullout/geometry/polyline.hpp"

namespace pullout {

namespace {

// The point at half the arc length of a line.
Point2 middle_of(const std::vector<Point2>& pts) {
  const double half = 0.5 * polyline_length(pts);
  double s = 0.0;
  for (std::size_t i = 1; i < pts.size(); ++i) {
    const double seg = std::hypot(pts[i].x - pts[i - 1].x, pts[i].y - pts[i - 1].y);
    if (s + seg >= half && seg > 0.0) {
      const double t = (half - s) / seg;
      return {pts[i - 1].x + t * (pts[i].x - pts[i - 1].x), pts[i - 1].y + t * (pts[i].y - pts[i - 1].y)};
    }
    s += seg;
  }
  return pts.back();
}

struct SegmentFoot {
  double distance{std::numeric_limits<double>::infinity()};
  double cross{0.0};  // > 0: the point is left of the segment's direction
};

// Which side of a polyline p lies on, judged at the nearest segment: > 0 left, < 0 right.
double side_of(const std::vector<Point2>& line, const Point2& p) {
  SegmentFoot best;
  for (std::size_t i = 1; i < line.size(); ++i) {
    const Point2& a = line[i - 1];
    const Point2& b = line[i];
    const double dx = b.x - a.x;
    const double dy = b.y - a.y;
    const double len2 = dx * dx + dy * dy;
    if (len2 <= 0.0) continue;
    const double t = std::clamp(((p.x - a.x) * dx + (p.y - a.y) * dy) / len2, 0.0, 1.0);
    const double d = std::hypot(a.x + t * dx - p.x, a.y + t * dy - p.y);
    if (d < best.distance) best = {d, dx * (p.y - a.y) - dy * (p.x - a.x)};
  }
  return best.cross;
}

void reverse_bound(LaneletBound& bound) {
  std::reverse(bound.points.begin(), bound.points.end());
  std::swap(bound.front_node, bound.back_node);
}

// Both bounds in the driving direction, the left one on the left (see lanelet_map.hpp). Each bound
// is judged against the other one as drawn, so the two decisions are independent.
void align(Lanelet& ll) {
  const bool reverse_right = side_of(ll.right.points, middle_of(ll.left.points)) < 0.0;
  const bool reverse_left = side_of(ll.left.points, middle_of(ll.right.points)) > 0.0;
  if (reverse_right) reverse_bound(ll.right);
  if (reverse_left) reverse_bound(ll.left);
  // A centerline member starts at the lanelet's entry: between the front points of the bounds.
  if (ll.centerline.size() >= 2) {
    const Point2 entry{0.5 * (ll.left.points.front().x + ll.right.points.front().x),
                       0.5 * (ll.left.points.front().y + ll.right.points.front().y)};
    const Point2& a = ll.centerline.front();
    const Point2& b = ll.centerline.back();
    if (std::hypot(b.x - entry.x, b.y - entry.y) < std::hypot(a.x - entry.x, a.y - entry.y)) {
      std::reverse(ll.centerline.begin(), ll.centerline.end());
    }
  }
}

double distance_point_segment(const Point2& p, const Point2& a, const Point2& b) {
  const double dx = b.x - a.x;
  const double dy = b.y - a.y;
  const double len2 = dx * dx + dy * dy;
  const double t = len2 > 0.0 ? std::clamp(((p.x - a.x) * dx + (p.y - a.y) * dy) / len2, 0.0, 1.0) : 0.0;
  return std::hypot(a.x + t * dx - p.x, a.y + t * dy - p.y);
}

bool inside(const std::vector<Point2>& ring, const Point2& p) {
  bool in = false;
  for (std::size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++) {
    const Point2& a = ring[i];
    const Point2& b = ring[j];
    if ((a.y > p.y) != (b.y > p.y) && p.x < (b.x - a.x) * (p.y - a.y) / (b.y - a.y) + a.x) in = !in;
  }
  return in;
}

double box_distance(const Aabb& b, const Point2& p) {
  const double dx = std::max({b.min.x() - p.x, 0.0, p.x - b.max.x()});
  const double dy = std::max({b.min.y() - p.y, 0.0, p.y - b.max.y()});
  return std::hypot(dx, dy);
}

}  // namespace

LaneletMap::LaneletMap(std::vector<Lanelet> lanelets) : lanelets_(std::move(lanelets)) {
  for (std::size_t i = 0; i < lanelets_.size(); ++i) {
    Lanelet& ll = lanelets_[i];
    align(ll);
    ll.length_m = 0.5 * (polyline_length(ll.left.points) + polyline_length(ll.right.points));
    ll.polygon = ll.left.points;
    ll.polygon.insert(ll.polygon.end(), ll.right.points.rbegin(), ll.right.points.rend());
    ll.box = Aabb{};
    for (const Point2& p : ll.polygon) ll.box.extend(to_vec(p));
    ll.successors.clear();
    ll.predecessors.clear();
    ll.left_neighbours.clear();
    ll.right_neighbours.clear();
    by_id_.emplace(ll.id, i);
  }
  build_topology();
  build_index();
}

void LaneletMap::build_topology() {
  // (left front node, right front node) -> lanelets starting there.
  std::map<std::pair<std::int64_t, std::int64_t>, std::vector<std::size_t>> starts;
  // way id -> lanelets using it as their left / right bound.
  std::unordered_map<std::int64_t, std::vector<std::size_t>> as_left;
  std::unordered_map<std::int64_t, std::vector<std::size_t>> as_right;
  for (std::size_t i = 0; i < lanelets_.size(); ++i) {
    const Lanelet& ll = lanelets_[i];
    starts[{ll.left.front_node, ll.right.front_node}].push_back(i);
    as_left[ll.left.way_id].push_back(i);
    as_right[ll.right.way_id].push_back(i);
  }
  for (std::size_t a = 0; a < lanelets_.size(); ++a) {
    Lanelet& la = lanelets_[a];
    const auto it = starts.find({la.left.back_node, la.right.back_node});
    if (it != starts.end()) {
      for (std::size_t b : it->second) {
        if (b == a) continue;
        la.successors.push_back(b);
        lanelets_[b].predecessors.push_back(a);
      }
    }
    // Left neighbour: its right bound is my left bound, drawn the same way after alignment.
    if (const auto n = as_right.find(la.left.way_id); n != as_right.end()) {
      for (std::size_t b : n->second) {
        if (b != a && lanelets_[b].right.front_node == la.left.front_node) la.left_neighbours.push_back(b);
      }
    }
    if (const auto n = as_left.find(la.right.way_id); n != as_left.end()) {
      for (std::size_t b : n->second) {
        if (b != a && lanelets_[b].left.front_node == la.right.front_node) la.right_neighbours.push_back(b);
      }
    }
  }
}

void LaneletMap::build_index() {
  for (std::size_t i = 0; i < lanelets_.size(); ++i) {
    index_.insert(lanelets_[i].box, static_cast<std::uint32_t>(i));
  }
}

std::optional<std::size_t> LaneletMap::find(std::int64_t id) const {
  const auto it = by_id_.find(id);
  if (it == by_id_.end()) return std::nullopt;
  return it->second;
}

std::size_t LaneletMap::count(LaneletSubtype subtype) const {
  return static_cast<std::size_t>(
      std::count_if(lanelets_.begin(), lanelets_.end(), [subtype](const Lanelet& l) { return l.subtype == subtype; }));
}

std::vector<std::size_t> LaneletMap::lanelets_containing(const Point2& p) const {
  std::vector<std::size_t> out;
  if (!std::isfinite(p.x) || !std::isfinite(p.y)) return out;
  index_.any_at(to_vec(p), [&](std::uint32_t i) {
    const Lanelet& ll = lanelets_[i];
    if (box_distance(ll.box, p) == 0.0 && inside(ll.polygon, p)) out.push_back(i);
    return false;
  });
  std::sort(out.begin(), out.end());
  return out;
}

double LaneletMap::distance_to(std::size_t index, const Point2& p) const {
  const std::vector<Point2>& ring = lanelets_[index].polygon;
  if (inside(ring, p)) return 0.0;
  double d = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++) {
    d = std::min(d, distance_point_segment(p, ring[j], ring[i]));
  }
  return d;
}

std::vector<std::size_t> LaneletMap::lanelets_near(const Point2& p, double radius) const {
  std::vector<std::size_t> candidates;
  if (!(radius >= 0.0) || !std::isfinite(radius) || !std::isfinite(p.x) || !std::isfinite(p.y)) return candidates;
  const Aabb query = Aabb{to_vec(p), to_vec(p)}.inflated(radius);
  if (index_.cell_count(query) > static_cast<double>(index_.occupied_cells())) {
    // A query wider than the map: looking at every lanelet is cheaper than at every cell.
    for (std::size_t i = 0; i < lanelets_.size(); ++i) {
      if (box_distance(lanelets_[i].box, p) <= radius) candidates.push_back(i);
    }
  } else {
    index_.any_in(query, [&](std::uint32_t i) {
      if (box_distance(lanelets_[i].box, p) <= radius) candidates.push_back(i);
      return false;
    });
  }
  // A lanelet spanning several cells is listed once per cell.
  std::sort(candidates.begin(), candidates.end());
  candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
  std::vector<std::size_t> out;
  for (std::size_t i : candidates) {
    if (distance_to(i, p) <= radius) out.push_back(i);
  }
  return out;
}

std::optional<Lane> to_lane(const Lanelet& lanelet) {
  if (lanelet.subtype == LaneletSubtype::kOther) return std::nullopt;
  Lane lane;
  lane.id = lanelet.id;
  lane.subtype = lanelet.subtype == LaneletSubtype::kRoadShoulder ? LaneSubtype::kRoadShoulder : LaneSubtype::kRoad;
  lane.left_bound = lanelet.left.points;
  lane.right_bound = lanelet.right.points;
  lane.centerline = lanelet.centerline;
  lane.speed_limit_mps = lanelet.speed_limit_mps;
  return lane;
}

const char* to_string(LaneletSubtype subtype) {
  switch (subtype) {
    case LaneletSubtype::kRoad:
      return "road";
    case LaneletSubtype::kRoadShoulder:
      return "road_shoulder";
    case LaneletSubtype::kOther:
      return "other";
  }
  return "?";
}

}  // namespace pullout
