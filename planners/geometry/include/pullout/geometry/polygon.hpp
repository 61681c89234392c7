// Simple polygons and axis-aligned boxes.
#pragma once

#include <algorithm>
#include <limits>
#include <vector>

#include "pullout/geometry/polyline.hpp"

namespace pullout {

using Polygon = std::vector<Vec2>;  // vertices in order, not closed (last != first)

struct Aabb {
  Vec2 min{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  Vec2 max{-std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};

  void extend(const Vec2& p) {
    min = min.cwiseMin(p);
    max = max.cwiseMax(p);
  }
  Aabb inflated(double d) const { return {min.array() - d, max.array() + d}; }
  bool contains(const Vec2& p) const {
    return p.x() >= min.x() && p.x() <= max.x() && p.y() >= min.y() && p.y() <= max.y();
  }
  bool overlaps(const Aabb& o) const {
    return min.x() <= o.max.x() && o.min.x() <= max.x() && min.y() <= o.max.y() && o.min.y() <= max.y();
  }
  bool valid() const { return min.x() <= max.x(); }
};

Aabb bounding_box(const Polygon& polygon);
// Signed area (counter-clockwise positive) [m^2].
double signed_area(const Polygon& polygon);
// Even-odd rule; points on the boundary may be reported either way.
bool point_in_polygon(const Polygon& polygon, const Vec2& p);
// Proper or touching intersection of segments ab and cd.
bool segments_intersect(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d);
// Distance from p to segment ab.
double distance_to_segment(const Vec2& p, const Vec2& a, const Vec2& b);

}  // namespace pullout
