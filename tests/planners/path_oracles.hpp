// Independent oracles for found paths, shared by the property tests: a plain polygon distance
// instead of FCL, and boundary sampling against raw lane polygons instead of the lane world's
// outline.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "pullout/collision/footprint.hpp"
#include "pullout/geometry/polygon.hpp"
#include "pullout/model/types.hpp"

namespace pullout::oracle {

inline bool segments_cross(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  const auto orient = [](const Vec2& p, const Vec2& q, const Vec2& r) {
    return (q.x() - p.x()) * (r.y() - p.y()) - (q.y() - p.y()) * (r.x() - p.x());
  };
  return orient(a, b, c) * orient(a, b, d) <= 0.0 && orient(c, d, a) * orient(c, d, b) <= 0.0;
}

inline double point_segment(const Vec2& p, const Vec2& a, const Vec2& b) {
  const Vec2 d = b - a;
  const double t = std::clamp((p - a).dot(d) / d.squaredNorm(), 0.0, 1.0);
  return (a + t * d - p).norm();
}

// Distance between two simple polygons, 0 when they touch or overlap.
inline double polygon_distance(const Polygon& A, const Polygon& B) {
  for (std::size_t i = 0; i < A.size(); ++i) {
    for (std::size_t j = 0; j < B.size(); ++j) {
      if (segments_cross(A[i], A[(i + 1) % A.size()], B[j], B[(j + 1) % B.size()])) return 0.0;
    }
  }
  if (point_in_polygon(A, B[0]) || point_in_polygon(B, A[0])) return 0.0;
  double d = std::numeric_limits<double>::infinity();
  for (const Vec2& p : A) {
    for (std::size_t j = 0; j < B.size(); ++j) d = std::min(d, point_segment(p, B[j], B[(j + 1) % B.size()]));
  }
  for (const Vec2& p : B) {
    for (std::size_t i = 0; i < A.size(); ++i) d = std::min(d, point_segment(p, A[i], A[(i + 1) % A.size()]));
  }
  return d;
}

inline Polygon lane_polygon(const Lane& lane) {
  Polygon p;
  for (const Point2& q : lane.left_bound) p.push_back(to_vec(q));
  for (auto it = lane.right_bound.rbegin(); it != lane.right_bound.rend(); ++it) p.push_back(to_vec(*it));
  return p;
}

// Every point of the footprint outline (every 5 cm), pulled 1 mm inwards so that a footprint
// flush with a lane edge counts as inside, lies in some lane.
inline bool footprint_in_lanes(const Footprint& f, const Pose2& pose, const std::vector<Polygon>& lanes) {
  Footprint shrunk{f.front - 1e-3, f.rear - 1e-3, f.left - 1e-3, f.right - 1e-3};
  const auto c = footprint_corners(shrunk, pose);
  for (std::size_t k = 0; k < 4; ++k) {
    const Vec2 a = c[k];
    const Vec2 b = c[(k + 1) % 4];
    const int n = static_cast<int>(std::ceil((b - a).norm() / 0.05));
    for (int i = 0; i <= n; ++i) {
      const Vec2 p = a + (b - a) * (static_cast<double>(i) / n);
      bool inside = false;
      for (const Polygon& l : lanes) inside = inside || point_in_polygon(l, p);
      if (!inside) return false;
    }
  }
  return true;
}

inline double direction_of(const PathWithLaneId& seg) {
  for (const auto& p : seg.points) {
    if (p.longitudinal_velocity_mps > 0.0) return 1.0;
    if (p.longitudinal_velocity_mps < 0.0) return -1.0;
  }
  return 0.0;
}

}  // namespace pullout::oracle
