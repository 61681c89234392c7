// Generated families of parallel parking spots on a single-lane street: a 3 m parking lane beside
// ONE 3.5 m road lane (no opposite lane to swing into), right-hand traffic (parking lane on the
// right, the vehicle pulls out to the left) and left-hand traffic (parking lane on the left,
// pulling out to the right), the vehicle 0.15-0.5 m from the kerb between two parked cars with
// 0.5-4 m free ahead and behind. The geometric planner runs alone (freespace off).
//
// Expectation (a driver's, stated as plain geometry in this file, not taken from the planner):
// after reversing as far as the car behind allows (to `kSmallestMargin` from it), the first move
// is a full-lock arc towards the road - at the radius R_min, or, when the rear corner on the kerb
// side would swing over the kerb's lane edge less the kerb-side margin, at the smallest radius
// whose swing fits. The kerb-side margin is lane_departure_margin m where the room beside the car
// allows it, and yields to what a car parked closer needs: with g the gap to the kerb and s the
// swing of the rear corner (behind the rear by m) at R_min,
//   m_kerb = clamp(g - s - 1 cm, 0, m)
// (a car 0.15 m from the kerb is not asked for 0.2 m; the road side keeps m). The outer front corner (on the kerb side)
// circles the arc's centre at hypot(front, R + half width), and passes the car ahead's rear corner on the road side; it
// clears that corner by kSmallestMargin when the room ahead g (after reversing) satisfies
//   (front + g)^2 + (R - w_car / 2)^2 >= (hypot(front, R + w) + kSmallestMargin)^2.
// Spots with g above that bound plus kFindTolerance must give a path; spots with g below it
// minus kNoPathTolerance cannot (every first arc has a radius >= R, which needs more room);
// between the two no claim is made.
//
// Every path found is checked by independent oracles written here: the footprint rectangle
// (expanded by lane_departure_margin, on the kerb side by m_kerb) inside the street's lane
// rectangle, the plain footprint inside the raw lane polygons (path_oracles.hpp), the plain footprint
// at least kSmallestMargin (less the chord tolerance) from both cars' rectangles, at poses
// interpolated every 5 cm along every partial path; a stop (velocity 0) at the end of every
// partial path but the last (the reverse leg, the stop to re-steer between the arcs); one pair
// per partial path; and the geometric part divided into exactly two forward segments.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

#include "../sampling.hpp"
#include "path_oracles.hpp"
#include "pullout/geometry/polyline.hpp"
#include "pullout/model/names.hpp"
#include "pullout/pipeline/start_planner.hpp"
#include "test_world.hpp"

namespace pullout {
namespace {

constexpr double kRoadHalfWidth = 1.75;  // [m] one 3.5 m road lane, y in [-1.75, 1.75]
constexpr double kParkingWidth = 3.0;    // [m]
constexpr double kStreetLength = 120.0;  // [m] x in [0, 120]
constexpr double kEgoX = 40.0;
constexpr double kCarLength = 4.5;
constexpr double kCarWidth = 1.9;
constexpr double kSmallestMargin = 0.1;  // [m] the last rung of collision_check_margins
// [m] The output path has points every arc_path_interval (1 m) on arcs of radius >= 5 m: poses
// interpolated on the chords lie within 1^2 / (8 * 5) = 2.5 cm of the arcs.
constexpr double kChordTolerance = 0.03;
constexpr double kFindTolerance = 0.25;    // [m] discrete end offsets, arcs that end early
constexpr double kNoPathTolerance = 0.05;  // [m] bisection of the last backward candidate, chords

struct Spot {
  bool right_hand;  // true: parking lane on the right of the eastbound road lane
  double kerb;      // [m] from the vehicle's kerb-side edge to the kerb
  double ahead;     // [m] free between the front bumper and the car ahead
  double behind;    // [m] free between the rear bumper and the car behind
};

std::ostream& operator<<(std::ostream& os, const Spot& s) {
  return os << (s.right_hand ? "right-hand" : "left-hand") << " kerb " << s.kerb << " ahead " << s.ahead << " behind "
            << s.behind;
}

// ---- the oracle's plain geometry ----

using Quad = std::array<Vec2, 4>;

// Rectangle front/rear/left/right [m] around (x, y) with heading yaw, counter-clockwise.
Quad rectangle(double x, double y, double yaw, double front, double rear, double left, double right) {
  const double c = std::cos(yaw);
  const double s = std::sin(yaw);
  const auto at = [&](double a, double b) { return Vec2(x + c * a - s * b, y + s * a + c * b); };
  return {at(front, left), at(-rear, left), at(-rear, -right), at(front, -right)};
}

double point_to_segment(const Vec2& p, const Vec2& a, const Vec2& b) {
  const Vec2 d = b - a;
  const double t = std::clamp((p - a).dot(d) / d.squaredNorm(), 0.0, 1.0);
  return (a + t * d - p).norm();
}

// Whether two convex quadrilaterals overlap: no edge normal of either separates them.
bool quads_overlap(const Quad& a, const Quad& b) {
  for (const Quad* q : {&a, &b}) {
    for (int i = 0; i < 4; ++i) {
      const Vec2 e = (*q)[(i + 1) % 4] - (*q)[i];
      const Vec2 n(-e.y(), e.x());
      double a0 = std::numeric_limits<double>::infinity(), a1 = -a0, b0 = a0, b1 = -a0;
      for (const Vec2& p : a) {
        a0 = std::min(a0, p.dot(n));
        a1 = std::max(a1, p.dot(n));
      }
      for (const Vec2& p : b) {
        b0 = std::min(b0, p.dot(n));
        b1 = std::max(b1, p.dot(n));
      }
      if (a1 < b0 || b1 < a0) return false;
    }
  }
  return true;
}

// Distance between two convex quadrilaterals (0 when they overlap): the closest pair of
// disjoint convex polygons always includes a vertex of one of them.
double quad_distance(const Quad& a, const Quad& b) {
  if (quads_overlap(a, b)) return 0.0;
  double d = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) {
      d = std::min(d, point_to_segment(a[i], b[j], b[(j + 1) % 4]));
      d = std::min(d, point_to_segment(b[i], a[j], a[(j + 1) % 4]));
    }
  }
  return d;
}

// ---- the street ----

struct Street {
  PullOutRequest request;
  double y_min{0.0};  // the lanes' union is the rectangle x in [0, kStreetLength], y in [y_min, y_max]
  double y_max{0.0};
  Quad car_ahead;
  Quad car_behind;
};

Street make_street(const Spot& s, const VehicleInfo& v) {
  Street st;
  PullOutRequest& r = st.request;
  r.vehicle_id = "family";
  r.request_id = 1;
  const double kerb_y = s.right_hand ? -kRoadHalfWidth - kParkingWidth : kRoadHalfWidth + kParkingWidth;
  const Lane road = test::straight_lane(1, LaneSubtype::kRoad, 0, kStreetLength, -kRoadHalfWidth, kRoadHalfWidth, 8.33);
  const Lane parking =
      s.right_hand ? test::straight_lane(2, LaneSubtype::kRoadShoulder, 0, kStreetLength, kerb_y, -kRoadHalfWidth, 8.33)
                   : test::straight_lane(2, LaneSubtype::kRoadShoulder, 0, kStreetLength, kRoadHalfWidth, kerb_y, 8.33);
  r.lanes = {road, parking};
  st.y_min = s.right_hand ? kerb_y : -kRoadHalfWidth;
  st.y_max = s.right_hand ? kRoadHalfWidth : kerb_y;
  const double y = s.right_hand ? kerb_y + s.kerb + v.base_to_right_m() : kerb_y - s.kerb - v.base_to_left_m();
  r.ego_pose = {kEgoX, y, 0.0};
  r.goal_pose = {110.0, 0.0, 0.0};
  // The parked cars stand in line with the vehicle.
  const double x_ahead = kEgoX + v.base_to_front_m() + s.ahead + kCarLength / 2;
  const double x_behind = kEgoX - v.base_to_rear_m() - s.behind - kCarLength / 2;
  r.objects = {test::parked_car(7, x_ahead, y), test::parked_car(8, x_behind, y)};
  const double h = kCarLength / 2;
  const double w = kCarWidth / 2;
  st.car_ahead = rectangle(x_ahead, y, 0.0, h, h, w, w);
  st.car_behind = rectangle(x_behind, y, 0.0, h, h, w, w);
  return st;
}

StartPlannerParameters family_parameters() {
  StartPlannerParameters p;
  p.search_priority = {PlannerType::kGeometric};
  p.freespace_planner.enable_freespace_planner = false;
  // Autoware skips backward candidates within 5 m of the car ahead (room for a shift); in a
  // parallel spot every pose behind is that close, and reversing is what a driver does first.
  p.collision_check_margin_from_front_object = 0.0;
  // The two-arc S alone (this file's bound); shunting is tested in test_geometric_shunts.cpp.
  p.geometric_pull_out_max_shunts = 0;
  return p;
}

// ---- the driver's expectation ----

// Room [m] between the front bumper and the car ahead after reversing as far as the car behind
// allows, less the room the first full-lock arc's outer front corner needs to clear it.
double r_min_of(const VehicleInfo& v, const StartPlannerParameters& p) {
  return v.wheel_base_m / std::tan(v.max_steer_angle_rad * p.geometric_pull_out_max_steer_angle_margin_scale);
}

// The margin the lane check keeps from the kerb (see the file comment).
double kerb_margin(const Spot& s, const VehicleInfo& v, const StartPlannerParameters& p) {
  const double m = p.lane_departure_margin;
  const double u = r_min_of(v, p) + (s.right_hand ? v.base_to_right_m() : v.base_to_left_m());
  const double swing = std::hypot(u, v.base_to_rear_m() + m) - u;
  return std::clamp(s.kerb - swing - 0.01, 0.0, m);
}

double spare_room(const Spot& s, const VehicleInfo& v, const StartPlannerParameters& p) {
  const double m = p.lane_departure_margin;
  const double r_min = r_min_of(v, p);
  // The kerb-side rear corner of the footprint expanded by m (by m_kerb sideways) swings towards
  // the kerb by hypot(R + w, rear) - (R + w); it has `room` before the kerb-side lane edge.
  const double mk = kerb_margin(s, v, p);
  const double w_kerb = (s.right_hand ? v.base_to_right_m() : v.base_to_left_m()) + mk;
  const double rear = v.base_to_rear_m() + m;
  const double room = s.kerb - mk;
  double r = r_min;
  while (std::hypot(r + w_kerb, rear) - (r + w_kerb) > room) r += 0.01;  // plain search, 1 cm
  const double w = s.right_hand ? v.base_to_right_m() : v.base_to_left_m();
  const double corner = std::hypot(v.base_to_front_m(), r + w) + kSmallestMargin;
  const double needed = std::sqrt(corner * corner - (r - kCarWidth / 2) * (r - kCarWidth / 2)) - v.base_to_front_m();
  const double reversed = std::max(0.0, s.behind - kSmallestMargin);
  return s.ahead + reversed - needed;
}

// ---- the family ----

std::vector<Spot> family() {
  std::vector<Spot> spots;
  for (bool right_hand : {true, false}) {
    for (double kerb : {0.15, 0.2, 0.25, 0.3, 0.4, 0.5}) {
      for (double ahead : {0.5, 1.0, 1.5, 2.0, 3.0, 4.0}) {
        for (double behind : {0.5, 1.0, 1.5, 2.0, 3.0, 4.0}) spots.push_back({right_hand, kerb, ahead, behind});
      }
    }
  }
  return spots;
}

double direction(const PathWithLaneId& seg) {
  for (const PathPoint& p : seg.points) {
    if (p.longitudinal_velocity_mps > 0.0) return 1.0;
    if (p.longitudinal_velocity_mps < 0.0) return -1.0;
  }
  return 0.0;
}

// The oracle's verdict on a found path; empty when it is drivable.
std::string check_path(const PullOutPath& path, const Spot& s, const Street& st, const VehicleInfo& v,
                       const StartPlannerParameters& p) {
  if (path.planner_type != PlannerType::kGeometric) return "planner " + std::string(to_string(path.planner_type));
  const auto& segs = path.partial_paths;
  if (path.pairs_terminal_velocity_and_accel.size() != segs.size()) return "pairs and partial paths differ in number";
  std::size_t forward = 0;
  for (std::size_t i = 0; i < segs.size(); ++i) {
    if (segs[i].points.size() < 2) return "partial path " + std::to_string(i) + " has fewer than 2 points";
    const double dir = direction(segs[i]);
    if (dir > 0.0) ++forward;
    if (dir < 0.0 && (i != 0 || segs.size() != 3)) return "a reverse segment other than a leading one";
    for (const PathPoint& pt : segs[i].points) {
      if (pt.longitudinal_velocity_mps * dir < 0.0) return "direction changes inside partial path " + std::to_string(i);
    }
    if (i + 1 < segs.size() && segs[i].points.back().longitudinal_velocity_mps != 0.0) {
      return "partial path " + std::to_string(i) + " does not end stopped";
    }
  }
  if (forward != 2) return "geometric part is " + std::to_string(forward) + " forward segments, not 2";
  const Pose2 end = segs.back().points.back().pose;
  if (std::abs(end.y) > 0.05 || std::abs(std::remainder(end.yaw, 2.0 * kPi)) > 0.02) return "does not end on the road";
  const double m = p.lane_departure_margin - kChordTolerance;
  const double mk = std::max(0.0, kerb_margin(s, v, p) - kChordTolerance);
  const double left = v.base_to_left_m();
  const double right = v.base_to_right_m();
  const std::vector<Polygon> lane_polygons{oracle::lane_polygon(st.request.lanes[0]),
                                           oracle::lane_polygon(st.request.lanes[1])};
  const Footprint plain{v.base_to_front_m(), v.base_to_rear_m(), left, right};
  for (std::size_t i = 0; i < segs.size(); ++i) {
    for (const Pose2& q : oracle::poses_along(segs[i], 0.05)) {  // every 5 cm at most
      if (!oracle::footprint_in_lanes(plain, q, lane_polygons)) {
        return "segment " + std::to_string(i) + ": footprint outside the lane polygons at x " + std::to_string(q.x);
      }
      const Quad lanes_fp = rectangle(q.x, q.y, q.yaw, v.base_to_front_m() + m, v.base_to_rear_m() + m,
                                      left + (s.right_hand ? m : mk), right + (s.right_hand ? mk : m));
      for (const Vec2& c : lanes_fp) {
        if (c.x() < 0.0 || c.x() > kStreetLength || c.y() < st.y_min || c.y() > st.y_max) {
          return "segment " + std::to_string(i) + ": footprint corner (" + std::to_string(c.x()) + ", " +
                 std::to_string(c.y()) + ") outside the lanes less the margin";
        }
      }
      const Quad fp = rectangle(q.x, q.y, q.yaw, v.base_to_front_m(), v.base_to_rear_m(), left, right);
      for (const Quad* car : {&st.car_ahead, &st.car_behind}) {
        const double d = quad_distance(fp, *car);
        if (d < kSmallestMargin - kChordTolerance) {
          return "segment " + std::to_string(i) + ": " + std::to_string(d) + " m from a parked car at x " +
                 std::to_string(q.x);
        }
      }
    }
  }
  return "";
}

struct FamilyCounts {
  int expected_found{0}, found_of_expected{0}, expected_none{0}, none_of_expected{0}, unclaimed{0}, unclaimed_found{0};
};

TEST(GeometricSingleLaneStreet, PullsOutOfEveryParallelSpotADriverWould) {
  const VehicleInfo v;
  const StartPlannerParameters p = family_parameters();
  const StartPlanner planner(v, p);
  FamilyCounts counts;
  // Per family (traffic side, kerb distance): paths found where the bound expects one, of how many.
  std::vector<std::pair<std::string, std::array<int, 2>>> per_family;
  const std::vector<Spot> spots = family();
  for (std::size_t i = 0; i < spots.size(); ++i) {
    if (!test::sampled(i)) continue;
    const Spot& s = spots[i];
    const Street st = make_street(s, v);
    const PlanningResult r = planner.plan(st.request, StopCondition());
    const double spare = spare_room(s, v, p);
    const bool found = r.outcome == PlanningResult::Outcome::kFound;
    if (found) {
      const std::string verdict = check_path(r.path, s, st, v, p);
      EXPECT_TRUE(verdict.empty()) << s << ": " << verdict;
    }
    if (spare >= kFindTolerance) {
      const std::string name =
          std::string(s.right_hand ? "right-hand" : "left-hand") + " kerb " + std::to_string(s.kerb).substr(0, 4);
      auto it = std::find_if(per_family.begin(), per_family.end(), [&name](const auto& f) { return f.first == name; });
      if (it == per_family.end()) it = per_family.insert(per_family.end(), {name, {0, 0}});
      it->second[0] += found ? 1 : 0;
      ++it->second[1];
      ++counts.expected_found;
      counts.found_of_expected += found ? 1 : 0;
      EXPECT_TRUE(found) << s << ": spare room " << spare
                         << " m, yet no path: " << (r.path.reasons.empty() ? "" : r.path.reasons.front());
    } else if (spare < -kNoPathTolerance) {
      ++counts.expected_none;
      counts.none_of_expected += found ? 0 : 1;
      EXPECT_FALSE(found) << s << ": short of room by " << -spare << " m, yet a path was found";
    } else {
      ++counts.unclaimed;
      counts.unclaimed_found += found ? 1 : 0;
    }
  }
  std::cout << "single-lane street family: found " << counts.found_of_expected << "/" << counts.expected_found
            << " expected, none " << counts.none_of_expected << "/" << counts.expected_none << " expected, found "
            << counts.unclaimed_found << "/" << counts.unclaimed << " unclaimed\n";
  for (const auto& [name, c] : per_family) std::cout << "  " << name << ": " << c[0] << "/" << c[1] << "\n";
  // The family must exercise both sides of the bound.
  EXPECT_GT(counts.expected_found, test::sampled_count(20));
  EXPECT_GT(counts.expected_none, test::sampled_count(5));
}

// Closer to the kerb than the rear corner's swing at R_min (0.14 m with the 0.2 m rear margin):
// the kerb-side margin yields to 0 and the first arc widens to the radius whose swing fits the gap.
// That radius was solved for a swing equal to the gap, which rounding then put over it by 2e-16 m,
// and the swing check refused every end pose (shoulders 10993 and 13518 of Autoware's
// road_shoulder map turned 10 degrees towards the kerb). The street is open ahead and behind.
TEST(GeometricSingleLaneStreet, WidensTheFirstArcJustEnoughCloserToTheKerbThanItsSwing) {
  const VehicleInfo v;
  const StartPlannerParameters p = family_parameters();
  const StartPlanner planner(v, p);
  for (const bool right_hand : {true, false}) {
    for (int cm = 4; cm <= 13; ++cm) {
      const Spot s{right_hand, 0.01 * cm, 20.0, 10.0};
      const Street st = make_street(s, v);
      const PlanningResult r = planner.plan(st.request, StopCondition());
      ASSERT_EQ(r.outcome, PlanningResult::Outcome::kFound)
          << s << ": " << (r.path.reasons.empty() ? "" : r.path.reasons.front());
      // Two forward segments (the S), after a reverse where the search backed up first.
      const std::string verdict = check_path(r.path, s, st, v, p);
      EXPECT_TRUE(verdict.empty()) << s << ": " << verdict;
    }
  }
}

// The backward search on the same street with the road blocked ahead (every planner attempt
// fails, so every start candidate shows in the evaluation table): candidates at most
// backward_search_resolution apart, the last one just clear of the car behind, by the oracle.
TEST(BackwardSearch, StepsNoLongerThanTheResolutionUpToTheCarBehind) {
  const VehicleInfo v;
  StartPlannerParameters p = family_parameters();
  ASSERT_DOUBLE_EQ(p.backward_search_resolution, 2.0);
  const StartPlanner planner(v, p);
  for (double behind : {0.7, 1.5, 3.0, 5.3}) {
    const Spot s{true, 0.4, 1.0, behind};
    Street st = make_street(s, v);
    Object barrier;
    barrier.id = 99;
    barrier.pose = {50.0, 0.0, 0.0};  // across the road where every S ends
    barrier.length_m = 40.0;
    barrier.width_m = 2.0;
    st.request.objects.push_back(barrier);
    const PlanningResult r = planner.plan(st.request, StopCondition());
    ASSERT_NE(r.outcome, PlanningResult::Outcome::kFound) << s;
    std::vector<double> backs;
    for (const PlannerAttempt& a : r.evaluation_table) {
      if (a.planner != PlannerType::kGeometric) continue;
      if (std::find(backs.begin(), backs.end(), a.backward_distance_m) == backs.end()) {
        backs.push_back(a.backward_distance_m);
      }
    }
    std::sort(backs.begin(), backs.end());
    ASSERT_GE(backs.size(), 2u) << s << ": no candidate behind the vehicle";
    EXPECT_DOUBLE_EQ(backs.front(), 0.0);
    for (std::size_t i = 1; i < backs.size(); ++i) {
      EXPECT_LE(backs[i] - backs[i - 1], p.backward_search_resolution + 1e-9) << s;
    }
    // The last candidate: at least the smallest margin from the car behind, and within 2 mm of it.
    const double last = backs.back();
    const Pose2 e = st.request.ego_pose;
    const Quad fp = rectangle(e.x - last, e.y, 0.0, v.base_to_front_m(), v.base_to_rear_m(), v.base_to_left_m(),
                              v.base_to_right_m());
    const double d = quad_distance(fp, st.car_behind);
    EXPECT_GE(d, kSmallestMargin - 1e-9) << s;
    EXPECT_LE(d, kSmallestMargin + 2e-3) << s;
  }
}

}  // namespace
}  // namespace pullout
