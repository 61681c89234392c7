// Generated parallel parking spots on a street (issue 12), shared by the shunting tests
// (test_geometric_shunts.cpp) and the benchmark (bench/bench_street_spots.cpp): the vehicle
// between two parked cars (4.5 m x 1.9 m) in a 3 m parking lane beside one 3.5 m road lane (or
// two: an opposite lane beyond), the parking lane on the right (right-hand traffic) or on the left
// (left-hand), on a straight street or one curving left with centerline radius `radius` (the
// parking lane then outside the bend for right-hand traffic, inside for left-hand).
//
// What "kerb" and "slack" mean, also on a bend: `kerb` is the distance from the vehicle's body to
// the kerb (the parking lane's outer edge, as given to the planner: a polyline through points 1 m
// apart) at its closest point; `slack` is the sum of the closest distances from the body to the
// car ahead and to the car behind, half each. On a straight street that is the lateral gap and
// the gaps along the street; on a bend a straight car tangent to the curve at its rear axle comes
// closer to an outer kerb at its front corner (0.21 m closer at R 30 m: a car placed "0.15 m"
// from it by its rear axle overlaps the kerb by 0.06 m), and gaps set in the road centerline's
// arc length shrink inside the bend and grow outside it (at R 30 m and 1.0 m of slack: 0.05 and
// 0.06 m inside instead of 0.5 m, 1.09 and 0.83 m outside); so both are solved for here
// (bisection on the true distances). Lanes, cars and distances are plain geometry written
// here and in path_oracles.hpp, not the planners' code.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <ostream>
#include <string>
#include <vector>

#include "path_oracles.hpp"
#include "pullout/model/types.hpp"
#include "pullout/vehicle/vehicle_info.hpp"

namespace pullout::street {

constexpr double kLaneWidth = 3.5;       // [m] road lanes
constexpr double kParkingWidth = 3.0;    // [m]
constexpr double kStreetLength = 120.0;  // [m] of road centerline, from s = 0
constexpr double kEgoS = 40.0;           // [m] the vehicle's rear axle along the road centerline
constexpr double kCarLength = 4.5;       // [m] the parked cars
constexpr double kCarWidth = 1.9;

struct Spot {
  bool right_hand{true};
  int road_lanes{1};
  double kerb{0.3};    // [m] from the vehicle's body to the kerb, at its closest point
  double slack{1.0};   // [m] free ahead and behind together (closest distances, half each)
  double radius{0.0};  // [m] of the road centerline, curving left; 0: straight
};

inline std::string describe(const Spot& s) {
  std::string out = std::string(s.right_hand ? "right-hand" : "left-hand") + ", " + std::to_string(s.road_lanes) +
                    " road lane(s), " +
                    (s.radius > 0.0 ? "R " + std::to_string(static_cast<int>(s.radius)) + " m" : "straight") +
                    ", kerb " + std::to_string(s.kerb) + " m, slack " + std::to_string(s.slack) + " m";
  return out;
}
inline std::ostream& operator<<(std::ostream& os, const Spot& s) { return os << describe(s); }

// The street frame (s along the road centerline of the vehicle's lane, y to its left) to the map.
inline Pose2 at(const Spot& sp, double s, double y) {
  if (sp.radius <= 0.0) return {s, y, 0.0};
  const double th = s / sp.radius;
  return {(sp.radius - y) * std::sin(th), sp.radius - (sp.radius - y) * std::cos(th), th};
}

inline std::vector<Point2> line(const Spot& sp, double y) {
  std::vector<Point2> out;
  for (double s = 0.0; s <= kStreetLength + 1e-9; s += 1.0) {
    const Pose2 p = at(sp, s, y);
    out.push_back({p.x, p.y});
  }
  return out;
}

inline Lane lane(const Spot& sp, std::int64_t id, LaneSubtype subtype, double y_right, double y_left) {
  Lane l;
  l.id = id;
  l.subtype = subtype;
  l.left_bound = line(sp, y_left);
  l.right_bound = line(sp, y_right);
  l.speed_limit_mps = 8.33;
  return l;
}

// Smallest distance from a convex polygon to a polyline (0 when they touch or cross).
inline double polygon_polyline_distance(const Polygon& poly, const std::vector<Point2>& pl) {
  double d = std::numeric_limits<double>::infinity();
  for (std::size_t j = 0; j + 1 < pl.size(); ++j) {
    const Vec2 a = to_vec(pl[j]);
    const Vec2 b = to_vec(pl[j + 1]);
    for (std::size_t i = 0; i < poly.size(); ++i) {
      const Vec2& p = poly[i];
      const Vec2& q = poly[(i + 1) % poly.size()];
      if (oracle::segments_cross(a, b, p, q)) return 0.0;
      d = std::min({d, oracle::point_segment(p, a, b), oracle::point_segment(a, p, q)});
    }
  }
  if (!pl.empty()) {
    for (std::size_t i = 0; i < poly.size(); ++i) {
      d = std::min(d, oracle::point_segment(to_vec(pl.back()), poly[i], poly[(i + 1) % poly.size()]));
    }
  }
  return d;
}

struct Street {
  PullOutRequest request;
  std::vector<Polygon> lanes;  // raw lane polygons (for the oracles)
  std::vector<Polygon> cars;   // the parked cars' rectangles
  double road_y{0.0};          // street-frame y of the vehicle's road lane centerline
  double kerb_gap{0.0};        // [m] the body's distance to the kerb polyline, as generated
  double gap_ahead{0.0};       // [m] the body's distance to the car ahead, as generated
  double gap_behind{0.0};      // [m] and to the car behind
};

inline Street make_street(const Spot& sp, const VehicleInfo& v, const std::string& vehicle_id = "spot") {
  Street st;
  PullOutRequest& r = st.request;
  r.vehicle_id = vehicle_id;
  r.request_id = 1;
  const double h = kLaneWidth / 2;
  r.lanes.push_back(lane(sp, 1, LaneSubtype::kRoad, -h, h));
  if (sp.road_lanes == 2) {
    r.lanes.push_back(sp.right_hand ? lane(sp, 3, LaneSubtype::kRoad, h, h + kLaneWidth)
                                    : lane(sp, 3, LaneSubtype::kRoad, -h - kLaneWidth, -h));
  }
  r.lanes.push_back(sp.right_hand ? lane(sp, 2, LaneSubtype::kRoadShoulder, -h - kParkingWidth, -h)
                                  : lane(sp, 2, LaneSubtype::kRoadShoulder, h, h + kParkingWidth));
  const double side = sp.right_hand ? -1.0 : 1.0;  // where the parking lane and the kerb are
  const double kerb_y = side * (h + kParkingWidth);
  const std::vector<Point2> kerb_line = line(sp, kerb_y);
  const auto body = [&](const Pose2& q) {
    return oracle::rectangle_at(v.base_to_front_m(), v.base_to_rear_m(), v.base_to_left_m(), v.base_to_right_m(), q);
  };
  // Laterally: from where the straight-street formula puts it, move the vehicle towards the kerb
  // by what its closest point is too far (the distance changes with y at a slope of about 1).
  double y = sp.right_hand ? kerb_y + sp.kerb + v.base_to_right_m() : kerb_y - sp.kerb - v.base_to_left_m();
  for (int i = 0; i < 20; ++i) {
    const double d = polygon_polyline_distance(body(at(sp, kEgoS, y)), kerb_line);
    if (d <= 0.0) {
      y -= side * 0.05;  // overlapping: step away from the kerb
      continue;
    }
    if (std::abs(d - sp.kerb) < 1e-6) break;
    y += side * (d - sp.kerb);
  }
  st.kerb_gap = polygon_polyline_distance(body(at(sp, kEgoS, y)), kerb_line);
  r.ego_pose = at(sp, kEgoS, y);
  r.goal_pose = at(sp, 110.0, 0.0);
  const Polygon ego = body(r.ego_pose);
  const auto car_at = [&](double s) {
    const double c = kCarLength / 2;
    const double w = kCarWidth / 2;
    return oracle::rectangle_at(c, c, w, w, at(sp, s, y));
  };
  // Along the street: the car's centre where its closest distance to the body is slack / 2
  // (the distance grows with |s - kEgoS| beyond contact), by bisection.
  const auto place = [&](double dir) {
    const double touching = dir > 0.0 ? v.base_to_front_m() + kCarLength / 2 : v.base_to_rear_m() + kCarLength / 2;
    double lo = kEgoS + dir * 0.5 * touching;               // overlapping
    double hi = kEgoS + dir * (touching + sp.slack + 5.0);  // beyond the gap
    for (int i = 0; i < 60; ++i) {
      const double mid = 0.5 * (lo + hi);
      if (oracle::polygon_distance(ego, car_at(mid)) < sp.slack / 2) {
        lo = mid;
      } else {
        hi = mid;
      }
    }
    return 0.5 * (lo + hi);
  };
  const double s_ahead = place(1.0);
  const double s_behind = place(-1.0);
  for (auto [id, s] : {std::pair<std::int64_t, double>{7, s_ahead}, {8, s_behind}}) {
    Object o;
    o.id = id;
    o.object_class = ObjectClass::kCar;
    o.pose = at(sp, s, y);
    o.length_m = kCarLength;
    o.width_m = kCarWidth;
    r.objects.push_back(o);
    st.cars.push_back(car_at(s));
  }
  st.gap_ahead = oracle::polygon_distance(ego, st.cars[0]);
  st.gap_behind = oracle::polygon_distance(ego, st.cars[1]);
  for (const Lane& l : r.lanes) st.lanes.push_back(oracle::lane_polygon(l));
  return st;
}

}  // namespace pullout::street
