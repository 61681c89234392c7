// Shunting out of tight parallel spots (issue 12): the vehicle 0.15-0.5 m from the kerb between two
// parked cars (4.5 m x 1.9 m, in line with it) with 3.0 down to 0.8 m free ahead and behind
// together (split evenly); right-hand traffic (parking lane on the right) and left-hand (on the
// left); one road lane (no opposite lane to swing into) or two. The shipped search (shift, then
// geometric with shunting) with freespace off, so that the lane planners alone answer.
//
// What a driver does, as the target: every spot with 1.0 m or more of slack is left. Claimed here
// (what the shunting manoeuvre reaches today): two road lanes, 0.3 m or more from the kerb, 1.0 m
// or more of slack; and in the tests below, 0.15 m from the kerb (straight) and a single road lane
// with 1.0 m or more (straight and on the 30 m bend). Not claimed: single road lanes on the 100 and
// 200 m bends, 0.8 m of slack; printed. Every path found is checked by oracles written
// independently of the planners (path_oracles.hpp and plain geometry here): at poses interpolated
// every 5 cm along every partial path, the bare body inside the raw lane polygons and at least the
// smallest collision margin (less the chord tolerance) from both cars' rectangles; each partial
// path drives one way; velocity 0 at the end of every partial path followed by one driving the
// other way; consecutive partial paths join (within 1 cm, same heading); one pair per partial path;
// the path ends on the road lane's centerline, parallel to it.
//
// And where nobody gets out, a clear no-path: less slack than twice the smallest margin (the
// start already has the cars closer than that), and a spot whose road is blocked beyond it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include "../sampling.hpp"
#include "path_oracles.hpp"
#include "pullout/model/names.hpp"
#include "pullout/pipeline/start_planner.hpp"
#include "street_spots.hpp"

namespace pullout {
namespace {

using street::kLaneWidth;
using street::Spot;
using street::Street;
constexpr double kEgoX = street::kEgoS;  // on a straight street s is x
// [m] Shunting moves have points every 10 cm: a pose interpolated on a chord of a 5 m arc lies
// within 0.1^2 / (8 * 5) = 0.25 mm of it; the S has points every arc_path_interval (1 m):
// within 1^2 / (8 * 5) = 2.5 cm.
constexpr double kChordTolerance = 0.03;
constexpr double kJoinTolerance = 0.01;  // [m] end of one partial path to the start of the next

Street make_spot(const Spot& s, const VehicleInfo& v) { return street::make_street(s, v, "shunt"); }

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
// `radius`: of the street's bend (0: straight), for where the road centerline is at the end.
std::string check_path(const PullOutPath& path, const Street& st, const VehicleInfo& v, double margin,
                       double radius = 0.0) {
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
  if (radius > 0.0) {
    // On the bend (centre (0, radius), curving left): the centerline is the circle of radius
    // `radius` - road_y, its heading the polar angle from the centre's bottom.
    const double off = std::hypot(end.x, end.y - radius) - (radius - st.road_y);
    const double yaw = std::atan2(end.x, radius - end.y);
    if (std::abs(off) > 0.05 || std::abs(std::remainder(end.yaw - yaw, kTwoPi)) > 0.02) {
      return "does not end on the road lane's centerline";
    }
  } else if (std::abs(end.y - st.road_y) > 0.05 || std::abs(std::remainder(end.yaw, kTwoPi)) > 0.02) {
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

// The failure message of a spot that was not left: the search's summary and the first reason.
std::string why_no_path(const PlanningResult& r) {
  return "no path: " + r.stop_reason + (r.path.reasons.empty() ? "" : " / " + r.path.reasons.front());
}

// Plans `s` with `planner`; a path found must pass the oracles (`radius`: of the bend, for where
// the path ends).
PlanningResult plan_checked(const StartPlanner& planner, const Spot& s, const VehicleInfo& v, double margin,
                            double radius = 0.0) {
  const Street st = make_spot(s, v);
  PlanningResult r = planner.plan(st.request, StopCondition());
  if (r.outcome == PlanningResult::Outcome::kFound) {
    const std::string verdict = check_path(r.path, st, v, margin, radius);
    EXPECT_TRUE(verdict.empty()) << s << ": " << verdict;
  }
  return r;
}

// As plan_checked, and the spot must be left.
void expect_leaves(const StartPlanner& planner, const Spot& s, const VehicleInfo& v, double margin,
                   double radius = 0.0) {
  const PlanningResult r = plan_checked(planner, s, v, margin, radius);
  EXPECT_EQ(r.outcome, PlanningResult::Outcome::kFound) << s << ": " << why_no_path(r);
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
  const std::vector<Spot> spots = family();
  for (std::size_t i = 0; i < spots.size(); ++i) {
    const Spot& s = spots[i];
    const bool claimed = s.slack >= 1.0 && s.road_lanes == 2 && s.kerb >= 0.3;
    expected += claimed ? 1 : 0;
    if (!test::sampled(i)) continue;
    const PlanningResult r = plan_checked(planner, s, v, margin);
    const bool found = r.outcome == PlanningResult::Outcome::kFound;
    if (found) most_changes = std::max(most_changes, direction_changes(r.path));
    if (claimed) {
      found_expected += found ? 1 : 0;
      EXPECT_TRUE(found) << s << ": " << why_no_path(r);
    } else {
      ++unclaimed;
      found_unclaimed += found ? 1 : 0;
    }
  }
  std::cout << "shunting family: " << found_expected << "/" << expected << " claimed, " << found_unclaimed << "/"
            << unclaimed << " of the others; at most " << most_changes << " direction changes\n";
  EXPECT_EQ(expected, 20);
  // The family exercises multi-move paths (reverse, forward, reverse, forward: 3 changes and more).
  if (!test::kUnderSanitizer) EXPECT_GE(most_changes, 3);
}

// One road lane (a one-way street: no opposite lane to swing into), straight, 0.3 and 0.5 m from
// the kerb, 1.0 to 3.0 m of slack: every spot is left, every path passes the oracles. After the
// shunts the vehicle stands turned across the single lane, and two turns at R_min (5.06 m) swing
// its front corner on the road side over the far edge while it straightens (by up to
// hypot(R + w, front) - (R + w) = 1.1 m); the exit at a gentler curvature fits the lane's width.
// Without those exits 8 of these 20 spots (1.2-2.0 m of slack) had no path; at 1.0 m 0.3 m from
// the kerb even they do not fit, and the vehicle first creeps away from the kerb (less turn is
// then needed to pass the car ahead).
TEST(GeometricShunts, LeavesSingleLaneSpotsWithAGentlerExit) {
  const VehicleInfo v;
  const StartPlannerParameters p = shipped_without_freespace();
  const StartPlanner planner(v, p);
  const double margin = smallest_margin(p);
  int spots = 0;
  for (bool right_hand : {true, false}) {
    for (double kerb : {0.3, 0.5}) {
      for (double slack : {3.0, 2.0, 1.5, 1.2, 1.0}) {
        if (test::sampled(static_cast<std::size_t>(spots)))
          expect_leaves(planner, {right_hand, 1, kerb, slack}, v, margin);
        ++spots;
      }
    }
  }
  EXPECT_EQ(spots, 20);
}

// 0.15 m from the kerb (how cars are parked), straight, one road lane or two, 1.0 to 3.0 m of
// slack: every spot is left, every path passes the oracles. Full-lock shunts from there take the
// rear corner on the kerb side to the kerb (each reverse arc moves it towards the kerb, and once
// the vehicle is turned about 10 degrees every reverse does) and wedge the vehicle; it first
// creeps away from the kerb (an S forward, straight back) and shunts from there. Without the
// creeping the spots with 1.0 and 1.5 m of slack had no path (8 of these 16).
TEST(GeometricShunts, LeavesSpotsCloseToTheKerbByCreepingAwayFirst) {
  const VehicleInfo v;
  const StartPlannerParameters p = shipped_without_freespace();
  const StartPlanner planner(v, p);
  const double margin = smallest_margin(p);
  int spots = 0;
  for (bool right_hand : {true, false}) {
    for (int road_lanes : {1, 2}) {
      for (double slack : {3.0, 2.0, 1.5, 1.0}) {
        if (test::sampled(static_cast<std::size_t>(spots)))
          expect_leaves(planner, {right_hand, road_lanes, 0.15, slack}, v, margin);
        ++spots;
      }
    }
  }
  EXPECT_EQ(spots, 16);
}

// The generator (street_spots.hpp) on bends: the body is `kerb` from the kerb polyline at its
// closest point and inside the raw lane polygons, and the cars are slack / 2 from it. Before, a
// car tangent to a 30 m bend at its rear axle, "0.15 m" from the outer kerb there, overlapped the
// kerb with its front corner (the start itself was invalid), and gaps set in centerline arc length
// were 0.05 m instead of 0.5 m inside the bend at 1.0 m of slack.
TEST(GeometricShunts, GeneratedSpotsOnBendsHaveTheirKerbDistanceAndSlack) {
  const VehicleInfo v;
  const Footprint body{v.base_to_front_m(), v.base_to_rear_m(), v.base_to_left_m(), v.base_to_right_m()};
  for (bool right_hand : {true, false}) {
    for (double radius : {30.0, 100.0}) {
      const Spot s{right_hand, 1, 0.15, 1.0, radius};
      const Street st = make_spot(s, v);
      EXPECT_NEAR(st.kerb_gap, 0.15, 1e-3) << s;
      EXPECT_NEAR(st.gap_ahead, 0.5, 1e-3) << s;
      EXPECT_NEAR(st.gap_behind, 0.5, 1e-3) << s;
      EXPECT_TRUE(oracle::footprint_in_lanes(body, st.request.ego_pose, st.lanes)) << s;
      // Outside the bend the body's farthest point from the bend's centre is a corner on the kerb
      // side: (R + |y_edge|, front) from the centre, at the kerb radius less 0.15 m.
      if (right_hand) {
        const double kerb_r = radius + street::kLaneWidth / 2 + street::kParkingWidth;
        const Pose2& q = st.request.ego_pose;
        const double axle_r = std::hypot(q.x, q.y - radius);
        const double corner_r = std::hypot(axle_r + v.base_to_right_m(), v.base_to_front_m());
        // The kerb polyline's chords (1 m) lie up to 1 / (8 R) inside its circle.
        EXPECT_NEAR(kerb_r - corner_r, 0.15, 1.0 / (8.0 * kerb_r) + 1e-3) << s;
      }
    }
  }
}

// On bends (the parking lane outside a left bend for right-hand traffic, inside it for
// left-hand), two road lanes, 0.3 and 0.5 m from the kerb, 1.0 to 3.0 m of slack: every spot is
// left, every path passes the oracles. With the old generator (gaps set in centerline arc length)
// the inside of the 30 m bend had far less room than its nominal slack (0.05 m instead of 0.5 m
// at 1.0 m) and its 1.0-1.5 m spots were not left; with true closest distances they are.
TEST(GeometricShunts, LeavesSpotsOnBendsWithAMetreOfSlack) {
  const VehicleInfo v;
  const StartPlannerParameters p = shipped_without_freespace();
  const StartPlanner planner(v, p);
  const double margin = smallest_margin(p);
  int spots = 0;
  for (bool right_hand : {true, false}) {
    for (double radius : {30.0, 100.0}) {
      for (double kerb : {0.3, 0.5}) {
        for (double slack : {3.0, 2.0, 1.5, 1.0}) {
          if (test::sampled(static_cast<std::size_t>(spots)))
            expect_leaves(planner, {right_hand, 2, kerb, slack, radius}, v, margin, radius);
          ++spots;
        }
      }
    }
  }
  EXPECT_EQ(spots, 32);
}

// One road lane on the 30 m bend, 1.0 m of slack, 0.15-0.5 m from the kerb, with the parking lane
// inside the bend (left-hand traffic) and outside it (right-hand): every spot is left, every path
// passes the oracles. The shunts of up to 22.5 degrees each try the exit only every 35-40 degrees
// of turn here (a forward and a reverse move), and the turns that pass the car ahead with the
// smallest margin and those whose exit still fits the one lane lie in between (right-hand, 0.5 m:
// at 31 degrees the best exit passes the car ahead 0.06 m off, at 71 degrees every exit leaves the
// lane); moves of 5 degrees, then 3, find them. Before those, four of these six spots had no path
// by the lane planners (left-hand 0.15, 0.3 and 0.5 m, right-hand 0.5 m), and two by any planner.
TEST(GeometricShunts, LeavesSingleLaneSpotsOnATightBendInSmallSteps) {
  const VehicleInfo v;
  const StartPlannerParameters p = shipped_without_freespace();
  const StartPlanner planner(v, p);
  const double margin = smallest_margin(p);
  int spots = 0;
  for (bool right_hand : {true, false}) {
    for (double kerb : {0.15, 0.3, 0.5}) {
      expect_leaves(planner, {right_hand, 1, kerb, 1.0, 30.0}, v, margin, 30.0);
      ++spots;
    }
  }
  EXPECT_EQ(spots, 6);
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
    const PlanningResult r = planner.plan(make_spot(s, v).request, StopCondition());
    EXPECT_EQ(r.outcome, PlanningResult::Outcome::kNoPath) << s;
  }
}

// Each change of direction of a shunting path comes with velocity 0, and the pairs say which way
// each partial path drives (the sign of its velocity).
TEST(GeometricShunts, PairsFollowTheDirectionOfEachPartialPath) {
  const VehicleInfo v;
  const StartPlanner planner(v, shipped_without_freespace());
  const Spot s{true, 2, 0.3, 1.0};
  const PlanningResult r = planner.plan(make_spot(s, v).request, StopCondition());
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
    const PlanningResult r = planner.plan(make_spot(s, v).request, StopCondition());
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
  Street st = make_spot(s, v);
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
