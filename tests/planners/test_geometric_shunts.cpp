// Shunting out of tight parallel spots (issue 12): the vehicle 0.15-0.5 m from the kerb between two
// parked cars (4.5 m x 1.9 m, in line with it) with 3.0 down to 0.8 m free ahead and behind
// together (split evenly); right-hand traffic (parking lane on the right) and left-hand (on the
// left); one road lane (no opposite lane to swing into) or two. The shipped search (shift, then
// geometric with shunting) with freespace off, so that the lane planners alone answer.
//
// What a driver does, as the target: every spot with 1.0 m or more of slack is left. Claimed here
// (what the shunting manoeuvre reaches today): two road lanes, 0.3 m or more from the kerb, 1.0 m
// or more of slack. Not yet: 0.15 m from the kerb (the reverse arcs take the rear corner to the
// kerb and the vehicle is wedged) and a single road lane below 2 m of slack (from a turned pose
// every exit swings the front corner over the far edge); those are printed, not claimed. Every path
// found is checked by oracles written independently of the planners (path_oracles.hpp and plain
// geometry here): at poses interpolated every 5 cm along every partial path, the bare body
// inside the raw lane polygons and at least the smallest collision margin (less the chord
// tolerance) from both cars' rectangles; each partial path drives one way; velocity 0 at the end
// of every partial path followed by one driving the other way; consecutive partial paths join
// (within 1 cm, same heading); one pair per partial path; the path ends on the road lane's
// centerline, parallel to it.
//
// And where nobody gets out, a clear no-path: less slack than twice the smallest margin (the
// start already has the cars closer than that), and a spot whose road is blocked beyond it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include "path_oracles.hpp"
#include "pullout/model/names.hpp"
#include "pullout/pipeline/start_planner.hpp"
#include "test_world.hpp"

namespace pullout {
namespace {

constexpr double kLaneWidth = 3.5;       // [m] road lanes
constexpr double kParkingWidth = 3.0;    // [m]
constexpr double kStreetLength = 120.0;  // [m] x in [0, 120]
constexpr double kEgoX = 40.0;
constexpr double kCarLength = 4.5;
constexpr double kCarWidth = 1.9;
// [m] Shunting moves have points every 10 cm: a pose interpolated on a chord of a 5 m arc lies
// within 0.1^2 / (8 * 5) = 0.25 mm of it; the S has points every arc_path_interval (1 m):
// within 1^2 / (8 * 5) = 2.5 cm.
constexpr double kChordTolerance = 0.03;
constexpr double kJoinTolerance = 0.01;  // [m] end of one partial path to the start of the next

struct Spot {
  bool right_hand;
  int road_lanes;
  double kerb;   // [m] from the vehicle's kerb-side edge to the kerb
  double slack;  // [m] free ahead and behind together
};

std::ostream& operator<<(std::ostream& os, const Spot& s) {
  return os << (s.right_hand ? "right-hand" : "left-hand") << ", " << s.road_lanes << " road lane(s), kerb " << s.kerb
            << " m, slack " << s.slack << " m";
}

struct Street {
  PullOutRequest request;
  std::vector<Polygon> lanes;
  std::vector<Polygon> cars;
  double road_y{0.0};  // centerline of the vehicle's road lane
};

Street make_street(const Spot& s, const VehicleInfo& v) {
  Street st;
  PullOutRequest& r = st.request;
  r.vehicle_id = "shunt";
  r.request_id = 1;
  const double h = kLaneWidth / 2;
  r.lanes.push_back(test::straight_lane(1, LaneSubtype::kRoad, 0, kStreetLength, -h, h, 8.33));
  if (s.road_lanes == 2) {
    r.lanes.push_back(s.right_hand
                          ? test::straight_lane(3, LaneSubtype::kRoad, 0, kStreetLength, h, h + kLaneWidth, 8.33)
                          : test::straight_lane(3, LaneSubtype::kRoad, 0, kStreetLength, -h - kLaneWidth, -h, 8.33));
  }
  const double kerb_y = s.right_hand ? -h - kParkingWidth : h + kParkingWidth;
  r.lanes.push_back(s.right_hand
                        ? test::straight_lane(2, LaneSubtype::kRoadShoulder, 0, kStreetLength, kerb_y, -h, 8.33)
                        : test::straight_lane(2, LaneSubtype::kRoadShoulder, 0, kStreetLength, h, kerb_y, 8.33));
  const double y = s.right_hand ? kerb_y + s.kerb + v.base_to_right_m() : kerb_y - s.kerb - v.base_to_left_m();
  r.ego_pose = {kEgoX, y, 0.0};
  r.goal_pose = {110.0, 0.0, 0.0};
  const double x_ahead = kEgoX + v.base_to_front_m() + s.slack / 2 + kCarLength / 2;
  const double x_behind = kEgoX - v.base_to_rear_m() - s.slack / 2 - kCarLength / 2;
  r.objects = {test::parked_car(7, x_ahead, y), test::parked_car(8, x_behind, y)};
  for (const Object& o : r.objects) {
    const double c = kCarLength / 2;
    const double w = kCarWidth / 2;
    st.cars.push_back(oracle::rectangle_at(c, c, w, w, o.pose));
  }
  for (const Lane& l : r.lanes) st.lanes.push_back(oracle::lane_polygon(l));
  return st;
}

StartPlannerParameters shipped_without_freespace() {
  StartPlannerParameters p;
  p.freespace_planner.enable_freespace_planner = false;
  return p;
}

double smallest_margin(const StartPlannerParameters& p) {
  return *std::min_element(p.collision_check_margins.begin(), p.collision_check_margins.end());
}

int direction_changes(const PullOutPath& path) {
  int n = 0;
  for (std::size_t k = 0; k + 1 < path.partial_paths.size(); ++k) {
    if (oracle::direction_of(path.partial_paths[k]) != oracle::direction_of(path.partial_paths[k + 1])) ++n;
  }
  return n;
}

// The oracles' verdict on a found path; empty when it is drivable.
std::string check_path(const PullOutPath& path, const Street& st, const VehicleInfo& v, double margin) {
  const auto& segs = path.partial_paths;
  if (segs.empty()) return "no partial paths";
  if (path.pairs_terminal_velocity_and_accel.size() != segs.size()) return "pairs and partial paths differ in number";
  const Footprint body{v.base_to_front_m(), v.base_to_rear_m(), v.base_to_left_m(), v.base_to_right_m()};
  for (std::size_t k = 0; k < segs.size(); ++k) {
    const auto& pts = segs[k].points;
    if (pts.size() < 2) return "partial path " + std::to_string(k) + " has fewer than 2 points";
    const double dir = oracle::direction_of(segs[k]);
    if (dir == 0.0) return "partial path " + std::to_string(k) + " does not move";
    for (const PathPoint& pt : pts) {
      if (pt.longitudinal_velocity_mps * dir < 0.0) return "direction changes inside partial path " + std::to_string(k);
    }
    if (k + 1 < segs.size()) {
      if (oracle::direction_of(segs[k + 1]) != dir && pts.back().longitudinal_velocity_mps != 0.0) {
        return "no stop at the change of direction after partial path " + std::to_string(k);
      }
      const Pose2& a = pts.back().pose;
      const Pose2& b = segs[k + 1].points.front().pose;
      if (std::hypot(a.x - b.x, a.y - b.y) > kJoinTolerance || std::abs(std::remainder(a.yaw - b.yaw, kTwoPi)) > 0.01) {
        return "partial paths " + std::to_string(k) + " and " + std::to_string(k + 1) + " do not join";
      }
    }
    // Poses beyond the end pose are the road centerline (in the lanes, far from the cars).
    for (const Pose2& q : oracle::poses_along(segs[k], 0.05)) {
      if (!oracle::footprint_in_lanes(body, q, st.lanes)) {
        return "partial path " + std::to_string(k) + ": body outside the lanes at (" + std::to_string(q.x) + ", " +
               std::to_string(q.y) + ")";
      }
      for (const Polygon& car : st.cars) {
        const double d = oracle::polygon_distance(oracle::rectangle_at(body, q), car);
        if (d < margin - kChordTolerance) {
          return "partial path " + std::to_string(k) + ": " + std::to_string(d) + " m from a parked car at (" +
                 std::to_string(q.x) + ", " + std::to_string(q.y) + ")";
        }
      }
    }
  }
  const Pose2 end = path.end_pose;
  if (std::abs(end.y - st.road_y) > 0.05 || std::abs(std::remainder(end.yaw, kTwoPi)) > 0.02) {
    return "does not end on the road lane's centerline";
  }
  return "";
}

std::vector<Spot> family() {
  std::vector<Spot> spots;
  for (bool right_hand : {true, false}) {
    for (int road_lanes : {1, 2}) {
      for (double kerb : {0.15, 0.3, 0.5}) {
        for (double slack : {3.0, 2.0, 1.5, 1.2, 1.0, 0.8}) spots.push_back({right_hand, road_lanes, kerb, slack});
      }
    }
  }
  return spots;
}

TEST(GeometricShunts, LeavesEveryParallelSpotWithAMetreOfSlack) {
  const VehicleInfo v;
  const StartPlannerParameters p = shipped_without_freespace();
  const StartPlanner planner(v, p);
  const double margin = smallest_margin(p);
  int expected = 0;
  int found_expected = 0;
  int unclaimed = 0;
  int found_unclaimed = 0;
  int most_changes = 0;
  for (const Spot& s : family()) {
    const Street st = make_street(s, v);
    const PlanningResult r = planner.plan(st.request, StopCondition());
    const bool found = r.outcome == PlanningResult::Outcome::kFound;
    if (found) {
      const std::string verdict = check_path(r.path, st, v, margin);
      EXPECT_TRUE(verdict.empty()) << s << ": " << verdict;
      most_changes = std::max(most_changes, direction_changes(r.path));
    }
    if (s.slack >= 1.0 && s.road_lanes == 2 && s.kerb >= 0.3) {
      ++expected;
      found_expected += found ? 1 : 0;
      EXPECT_TRUE(found) << s << ": no path: " << r.stop_reason
                         << (r.path.reasons.empty() ? "" : " / " + r.path.reasons.front());
    } else {
      ++unclaimed;
      found_unclaimed += found ? 1 : 0;
    }
  }
  std::cout << "shunting family: " << found_expected << "/" << expected << " claimed, " << found_unclaimed << "/"
            << unclaimed << " of the others; at most " << most_changes << " direction changes\n";
  EXPECT_EQ(expected, 20);
  // The family exercises multi-move paths (reverse, forward, reverse, forward: 3 changes and more).
  EXPECT_GE(most_changes, 3);
}

// The same spots with shunting off: the tight ones are not left (what the shunts add), so the
// family above does test them.
TEST(GeometricShunts, WithoutShuntsTheTightSpotsHaveNoPath) {
  const VehicleInfo v;
  StartPlannerParameters p = shipped_without_freespace();
  p.geometric_pull_out_max_shunts = 0;
  const StartPlanner planner(v, p);
  for (bool right_hand : {true, false}) {
    const Spot s{right_hand, 1, 0.3, 1.0};
    const PlanningResult r = planner.plan(make_street(s, v).request, StopCondition());
    EXPECT_EQ(r.outcome, PlanningResult::Outcome::kNoPath) << s;
  }
}

// Each change of direction of a shunting path comes with velocity 0, and the pairs say which way
// each partial path drives (the sign of its velocity).
TEST(GeometricShunts, PairsFollowTheDirectionOfEachPartialPath) {
  const VehicleInfo v;
  const StartPlanner planner(v, shipped_without_freespace());
  const Spot s{true, 2, 0.3, 1.0};
  const PlanningResult r = planner.plan(make_street(s, v).request, StopCondition());
  ASSERT_EQ(r.outcome, PlanningResult::Outcome::kFound) << r.stop_reason;
  EXPECT_EQ(r.path.planner_type, PlannerType::kGeometric);
  ASSERT_EQ(r.path.pairs_terminal_velocity_and_accel.size(), r.path.partial_paths.size());
  EXPECT_GE(direction_changes(r.path), 3);
  for (std::size_t k = 0; k < r.path.partial_paths.size(); ++k) {
    const double dir = oracle::direction_of(r.path.partial_paths[k]);
    const auto& pair = r.path.pairs_terminal_velocity_and_accel[k];
    EXPECT_GT(pair.velocity_mps * dir, 0.0) << "partial path " << k;
  }
  // The evaluation table says the single moves failed at every margin, then shunting succeeded.
  ASSERT_FALSE(r.evaluation_table.empty());
  EXPECT_EQ(r.evaluation_table.back().outcome, AttemptOutcome::kSuccess);
  EXPECT_EQ(r.evaluation_table.back().detail, "shunting");
}

// Less slack than twice the smallest collision margin: the cars are closer than that margin at the
// start already, so no path keeps it; the answer is a stop path with the reasons.
TEST(GeometricShunts, NoRoomForTheMarginIsAClearNoPath) {
  const VehicleInfo v;
  const StartPlannerParameters p = shipped_without_freespace();
  const StartPlanner planner(v, p);
  const double slack = 2.0 * smallest_margin(p) - 0.02;
  for (bool right_hand : {true, false}) {
    const Spot s{right_hand, 2, 0.3, slack};
    const PlanningResult r = planner.plan(make_street(s, v).request, StopCondition());
    ASSERT_EQ(r.outcome, PlanningResult::Outcome::kNoPath) << s;
    EXPECT_FALSE(r.timed_out);
    EXPECT_FALSE(r.path.found);
    EXPECT_FALSE(r.path.reasons.empty());
    for (const auto& seg : r.path.partial_paths) {
      for (const PathPoint& pt : seg.points) EXPECT_EQ(pt.longitudinal_velocity_mps, 0.0);
    }
  }
}

// The road blocked beyond the spot (a barrier across both lanes from 2 m to 40 m ahead of the car
// ahead): shunting turns the vehicle out but no S reaches the road; a no-path whose evaluation
// table names the shunting attempt and why it stopped.
TEST(GeometricShunts, BlockedRoadIsAClearNoPathNamingTheShunts) {
  const VehicleInfo v;
  const StartPlanner planner(v, shipped_without_freespace());
  const Spot s{true, 1, 0.3, 1.0};
  Street st = make_street(s, v);
  Object barrier;
  barrier.id = 99;
  barrier.pose = {kEgoX + 22.0, 0.0, 0.0};
  barrier.length_m = 36.0;
  barrier.width_m = kLaneWidth;
  st.request.objects.push_back(barrier);
  const PlanningResult r = planner.plan(st.request, StopCondition());
  ASSERT_EQ(r.outcome, PlanningResult::Outcome::kNoPath);
  const auto shunt_row = std::find_if(r.evaluation_table.begin(), r.evaluation_table.end(),
                                      [](const PlannerAttempt& a) { return a.detail.rfind("shunting: ", 0) == 0; });
  ASSERT_NE(shunt_row, r.evaluation_table.end()) << "no shunting attempt in the evaluation table";
  EXPECT_EQ(shunt_row->planner, PlannerType::kGeometric);
  EXPECT_NE(shunt_row->outcome, AttemptOutcome::kSuccess);
}

}  // namespace
}  // namespace pullout
