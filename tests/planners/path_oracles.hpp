// Independent oracles for found paths, shared by the property tests: a separating-axis overlap
// test and a vertex-to-edge distance instead of FCL or the freespace grid checker, boundary
// sampling against raw lane polygons instead of the lane world's outline, Menger curvature of
// three consecutive points, and poses interpolated between path points. Nothing here calls a
// planner's collision checker.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "pullout/collision/footprint.hpp"
#include "pullout/geometry/angle.hpp"
#include "pullout/geometry/polygon.hpp"
#include "pullout/lane_planners/lane_planner_parameters.hpp"
#include "pullout/model/types.hpp"
#include "pullout/vehicle/vehicle_info.hpp"

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

// ---- separating-axis test (convex polygons) ----

inline bool is_convex(const Polygon& p) {
  if (p.size() < 3) return false;
  double sign = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec2 e1 = p[(i + 1) % p.size()] - p[i];
    const Vec2 e2 = p[(i + 2) % p.size()] - p[(i + 1) % p.size()];
    const double c = e1.x() * e2.y() - e1.y() * e2.x();
    if (c == 0.0) continue;
    if (sign == 0.0) sign = c;
    if ((c > 0.0) != (sign > 0.0)) return false;
  }
  return true;
}

// Largest gap [m] between the projections of two convex polygons on the normals of their edges:
// > 0 means an axis separates them (they are disjoint), <= 0 means they overlap or touch (for
// convex polygons some edge normal separates any disjoint pair). The gap is a lower bound of
// their distance, exact when the closest features are an edge and a vertex facing it.
inline double separating_gap(const Polygon& A, const Polygon& B) {
  double best = -std::numeric_limits<double>::infinity();
  const auto axes_of = [&](const Polygon& P) {
    for (std::size_t i = 0; i < P.size(); ++i) {
      const Vec2 e = P[(i + 1) % P.size()] - P[i];
      const double n = e.norm();
      if (n < 1e-12) continue;
      const Vec2 axis(-e.y() / n, e.x() / n);
      double a_min = std::numeric_limits<double>::infinity(), a_max = -a_min;
      double b_min = a_min, b_max = -a_min;
      for (const Vec2& p : A) {
        a_min = std::min(a_min, p.dot(axis));
        a_max = std::max(a_max, p.dot(axis));
      }
      for (const Vec2& p : B) {
        b_min = std::min(b_min, p.dot(axis));
        b_max = std::max(b_max, p.dot(axis));
      }
      best = std::max(best, std::max(b_min - a_max, a_min - b_max));
    }
  };
  axes_of(A);
  axes_of(B);
  return best;
}

inline bool convex_overlap(const Polygon& A, const Polygon& B) { return separating_gap(A, B) <= 0.0; }

// Overlap of two simple polygons (touching counts): the separating-axis test when both are
// convex, otherwise crossing edges or one polygon inside the other.
inline bool polygons_overlap(const Polygon& A, const Polygon& B) {
  if (is_convex(A) && is_convex(B)) return convex_overlap(A, B);
  for (std::size_t i = 0; i < A.size(); ++i) {
    for (std::size_t j = 0; j < B.size(); ++j) {
      if (segments_cross(A[i], A[(i + 1) % A.size()], B[j], B[(j + 1) % B.size()])) return true;
    }
  }
  return point_in_polygon(A, B[0]) || point_in_polygon(B, A[0]);
}

// Distance between two simple polygons, 0 when they touch or overlap: for disjoint polygons the
// closest pair of points always includes a vertex of one of them, so the smallest vertex-to-edge
// distance is exact.
inline double polygon_distance(const Polygon& A, const Polygon& B) {
  if (polygons_overlap(A, B)) return 0.0;
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
// With closed_gap > 0, a point outside every lane still counts as inside when the distances to
// the two nearest lanes add up to at most closed_gap (it lies in a sliver between them).
inline bool footprint_in_lanes(const Footprint& f, const Pose2& pose, const std::vector<Polygon>& lanes,
                               double closed_gap = 0.0) {
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
      if (!inside && closed_gap > 0.0) {
        double d1 = std::numeric_limits<double>::infinity();
        double d2 = d1;
        for (const Polygon& l : lanes) {
          double d = std::numeric_limits<double>::infinity();
          for (std::size_t e = 0; e < l.size(); ++e) d = std::min(d, point_segment(p, l[e], l[(e + 1) % l.size()]));
          if (d < d1) {
            d2 = d1;
            d1 = d;
          } else if (d < d2) {
            d2 = d;
          }
        }
        inside = d1 + d2 <= closed_gap;
      }
      if (!inside) return false;
    }
  }
  return true;
}

// The largest expansion e in [0, cap] [m] of one side of `base` (`side` points at the member: front,
// rear, left or right) with which footprint_in_lanes still holds at `pose`, by bisection to 0.1 mm;
// -1 when `base` itself is not inside.
inline double side_gap(const Footprint& base, double Footprint::*side, const Pose2& pose,
                       const std::vector<Polygon>& lanes, double cap) {
  const auto inside = [&](double e) {
    Footprint f = base;
    f.*side += e;
    return footprint_in_lanes(f, pose, lanes);
  };
  if (!inside(0.0)) return -1.0;
  if (inside(cap)) return cap;
  double lo = 0.0;
  double hi = cap;
  while (hi - lo > 1e-4) {
    const double mid = 0.5 * (lo + hi);
    (inside(mid) ? lo : hi) = mid;
  }
  return lo;
}

// The rectangle front/rear/left/right [m] around base_link at `pose`, counter-clockwise; written
// here rather than taken from the planners' footprint code.
inline Polygon rectangle_at(double front, double rear, double left, double right, const Pose2& pose) {
  const double c = std::cos(pose.yaw);
  const double s = std::sin(pose.yaw);
  const auto at = [&](double x, double y) { return Vec2(pose.x + c * x - s * y, pose.y + s * x + c * y); };
  return {at(front, left), at(-rear, left), at(-rear, -right), at(front, -right)};
}
inline Polygon rectangle_at(const Footprint& f, const Pose2& pose) {
  return rectangle_at(f.front, f.rear, f.left, f.right, pose);
}

// Curvature [1/m] of the circle through a, b, c (Menger curvature: 4 area / product of the
// sides), signed (> 0 turning left); 0 for coincident points.
inline double menger_curvature(const Vec2& a, const Vec2& b, const Vec2& c) {
  const double cross = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
  const double denom = (b - a).norm() * (c - b).norm() * (c - a).norm();
  return denom < 1e-12 ? 0.0 : 2.0 * cross / denom;
}

// Poses between consecutive points of a segment, every `step` metres at most (position and
// heading interpolated linearly, the heading the short way round), both ends included.
inline std::vector<Pose2> poses_along(const PathWithLaneId& seg, double step) {
  std::vector<Pose2> out;
  for (std::size_t i = 0; i + 1 < seg.points.size(); ++i) {
    const Pose2& a = seg.points[i].pose;
    const Pose2& b = seg.points[i + 1].pose;
    const int n = std::max(1, static_cast<int>(std::ceil(std::hypot(b.x - a.x, b.y - a.y) / step)));
    const double dyaw = std::remainder(b.yaw - a.yaw, 2.0 * kPi);
    for (int k = 0; k < n; ++k) {
      const double t = static_cast<double>(k) / n;
      out.push_back({a.x + t * (b.x - a.x), a.y + t * (b.y - a.y), a.yaw + t * dyaw});
    }
  }
  if (!seg.points.empty()) out.push_back(seg.points.back().pose);
  return out;
}

// Whether polygon `poly` (map frame) overlaps an occupied cell of the grid (unknown or >= threshold;
// touching counts) or reaches outside the grid, which counts as occupied. Exact: the polygon is
// taken into the grid frame, and each occupied cell under its bounding box is tested as a square
// with the separating-axis test.
inline bool overlaps_grid(const OccupancyGrid& g, int threshold, const Polygon& poly) {
  const double c = std::cos(g.origin.yaw);
  const double s = std::sin(g.origin.yaw);
  Polygon local;
  double x_min = std::numeric_limits<double>::infinity(), y_min = x_min, x_max = -x_min, y_max = -x_min;
  for (const Vec2& p : poly) {
    const double dx = p.x() - g.origin.x;
    const double dy = p.y() - g.origin.y;
    local.emplace_back(c * dx + s * dy, -s * dx + c * dy);
    x_min = std::min(x_min, local.back().x());
    x_max = std::max(x_max, local.back().x());
    y_min = std::min(y_min, local.back().y());
    y_max = std::max(y_max, local.back().y());
  }
  const double r = g.resolution_m;
  if (x_min < 0.0 || y_min < 0.0 || x_max > g.width * r || y_max > g.height * r) return true;
  const int i0 = std::max(0, static_cast<int>(std::floor(x_min / r)) - 1);
  const int i1 = std::min(static_cast<int>(g.width) - 1, static_cast<int>(std::floor(x_max / r)) + 1);
  const int j0 = std::max(0, static_cast<int>(std::floor(y_min / r)) - 1);
  const int j1 = std::min(static_cast<int>(g.height) - 1, static_cast<int>(std::floor(y_max / r)) + 1);
  for (int j = j0; j <= j1; ++j) {
    for (int i = i0; i <= i1; ++i) {
      const int v = g.data[static_cast<std::size_t>(j) * g.width + i];
      if (v >= 0 && v < threshold) continue;
      const Polygon cell{{i * r, j * r}, {(i + 1) * r, j * r}, {(i + 1) * r, (j + 1) * r}, {i * r, (j + 1) * r}};
      if (convex_overlap(cell, local)) return true;
    }
  }
  return false;
}

// The footprint the geometric planner keeps inside the lanes from `start` (its rule, restated
// here with the oracle's own gap measurement on the raw lane polygons): lane_departure_margin m on
// the road side (towards `end`); at the front and the rear m, or the start's gap there if smaller;
// on the kerb side the start's gap g less the swing s of the rear corner on a first arc at R_min,
// less 1 cm, within [min(lane_departure_check_expansion_margin, m), m]. 2 mm are left for the two
// bisections.
inline Footprint geometric_lane_footprint(const VehicleInfo& v, const LanePlannerParameters& p, const Pose2& start,
                                          const Pose2& end, const std::vector<Polygon>& all_lanes) {
  const double m = p.lane_departure_margin;
  // The gaps are measured up to m + 1 m: only the lanes within reach of the footprint count.
  const double reach = vehicle_footprint(v).bounding_radius() + m + 2.0;
  std::vector<Polygon> lanes;
  for (const Polygon& l : all_lanes) {
    double d = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < l.size(); ++i)
      d = std::min(d, point_segment(to_vec(start), l[i], l[(i + 1) % l.size()]));
    if (d <= reach || point_in_polygon(l, to_vec(start))) lanes.push_back(l);
  }
  const Footprint plain = vehicle_footprint(v);
  Footprint f = plain;
  f.front += std::max(0.0, side_gap(plain, &Footprint::front, start, lanes, m));
  f.rear += std::max(0.0, side_gap(plain, &Footprint::rear, start, lanes, m));
  const double lateral_of_end = -std::sin(start.yaw) * (end.x - start.x) + std::cos(start.yaw) * (end.y - start.y);
  double Footprint::*road = lateral_of_end > 0.0 ? &Footprint::left : &Footprint::right;
  double Footprint::*kerb = lateral_of_end > 0.0 ? &Footprint::right : &Footprint::left;
  const double r_min =
      v.wheel_base_m / std::tan(v.max_steer_angle_rad * p.geometric_pull_out_max_steer_angle_margin_scale);
  const double gap = std::max(0.0, side_gap(f, kerb, start, lanes, m + 1.0));
  const double u = r_min + plain.*kerb;
  const double swing = std::hypot(u, f.rear) - u;
  const double floor = std::min(p.lane_departure_check_expansion_margin, m);
  f.*kerb += std::max(0.0, std::clamp(gap - swing - 0.01, floor, m) - 2e-3);
  f.*road += m;
  return f;
}

inline double direction_of(const PathWithLaneId& seg) {
  for (const auto& p : seg.points) {
    if (p.longitudinal_velocity_mps > 0.0) return 1.0;
    if (p.longitudinal_velocity_mps < 0.0) return -1.0;
  }
  return 0.0;
}

}  // namespace pullout::oracle
