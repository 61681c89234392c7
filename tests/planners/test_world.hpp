// Small worlds built in code for the core's unit tests (scenario files cover the same ground
// end to end through the YAML loader).
#pragma once

#include <cmath>
#include <vector>

#include "pullout/geometry/angle.hpp"
#include "pullout/model/types.hpp"

namespace pullout::test {

inline Lane straight_lane(std::int64_t id, LaneSubtype subtype, double x0, double x1, double y_right, double y_left,
                          double speed = 13.89) {
  Lane l;
  l.id = id;
  l.subtype = subtype;
  l.left_bound = {{x0, y_left}, {x1, y_left}};
  l.right_bound = {{x0, y_right}, {x1, y_right}};
  l.speed_limit_mps = speed;
  return l;
}

// A 100 m straight road (y in [-1.75, 1.75]) with a 3 m shoulder on its left (y in [1.75, 4.75]);
// the vehicle stands on the shoulder centre at x = 10, the goal is on the road at x = 90.
inline PullOutRequest straight_shoulder_request() {
  PullOutRequest r;
  r.vehicle_id = "test";
  r.request_id = 1;
  r.lanes = {straight_lane(1, LaneSubtype::kRoad, 0, 100, -1.75, 1.75),
             straight_lane(2, LaneSubtype::kRoadShoulder, 0, 100, 1.75, 4.75)};
  r.ego_pose = {10.0, 3.25, 0.0};
  r.goal_pose = {90.0, 0.0, 0.0};
  return r;
}

// Points of an arc of radius R around (cx, cy) from angle a0 to a1, every `step` metres.
inline std::vector<Point2> arc_points(double cx, double cy, double radius, double a0, double a1, double step) {
  std::vector<Point2> pts;
  const int n = std::max(2, static_cast<int>(std::ceil(std::abs(a1 - a0) * radius / step)) + 1);
  for (int i = 0; i < n; ++i) {
    const double a = a0 + (a1 - a0) * i / (n - 1);
    pts.push_back({cx + radius * std::cos(a), cy + radius * std::sin(a)});
  }
  return pts;
}

// A road curving left with centerline radius 60 m over 90 degrees, preceded by a 30 m straight,
// with a shoulder on the right (outside of the bend); the vehicle stands on the shoulder.
inline PullOutRequest curved_road_request() {
  PullOutRequest r;
  r.vehicle_id = "test";
  r.request_id = 2;
  const double R = 60.0;
  // Straight part from x = -30 to 0 along +x, then a left arc centred at (0, R).
  Lane road_straight = straight_lane(1, LaneSubtype::kRoad, -30, 0, -1.75, 1.75);
  Lane shoulder_straight = straight_lane(11, LaneSubtype::kRoadShoulder, -30, 0, -4.75, -1.75);
  Lane road_arc;
  road_arc.id = 2;
  road_arc.left_bound = arc_points(0, R, R - 1.75, -kPi / 2, 0.0, 1.0);
  road_arc.right_bound = arc_points(0, R, R + 1.75, -kPi / 2, 0.0, 1.0);
  Lane shoulder_arc;
  shoulder_arc.id = 12;
  shoulder_arc.subtype = LaneSubtype::kRoadShoulder;
  shoulder_arc.left_bound = arc_points(0, R, R + 1.75, -kPi / 2, 0.0, 1.0);
  shoulder_arc.right_bound = arc_points(0, R, R + 4.75, -kPi / 2, 0.0, 1.0);
  r.lanes = {road_straight, road_arc, shoulder_straight, shoulder_arc};
  r.ego_pose = {-20.0, -3.25, 0.0};
  r.goal_pose = {R, R, kPi / 2};
  return r;
}

inline Object parked_car(std::int64_t id, double x, double y, double yaw = 0.0) {
  Object o;
  o.id = id;
  o.object_class = ObjectClass::kCar;
  o.pose = {x, y, yaw};
  o.length_m = 4.5;
  o.width_m = 1.9;
  return o;
}

}  // namespace pullout::test
