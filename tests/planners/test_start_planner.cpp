#include "pullout/pipeline/start_planner.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <limits>
#include <string>

#include "pullout/collision/footprint.hpp"
#include "pullout/collision/object_checker.hpp"
#include "pullout/config/scenario.hpp"
#include "pullout/geometry/angle.hpp"
#include "pullout/lanes/lane_world.hpp"
#include "pullout/model/names.hpp"
#include "test_world.hpp"

namespace pullout {
namespace {

const StartPlanner& default_planner() {
  static const StartPlanner planner(VehicleInfo{}, StartPlannerParameters{});
  return planner;
}

// Shift from the current pose only: the margin ladder alone decides.
const StartPlanner& shift_only_planner() {
  static const StartPlanner planner = [] {
    StartPlannerParameters p;
    p.enable_back = false;
    p.search_priority = {PlannerType::kShift};
    p.freespace_planner.enable_freespace_planner = false;
    return StartPlanner(VehicleInfo{}, p);
  }();
  return planner;
}

bool has_issue(const PlanningResult& r, const std::string& field) {
  for (const auto& i : r.issues) {
    if (i.field == field) return true;
  }
  return false;
}

// Smallest clearance of the footprint along the path up to the end pose.
double min_clearance(const PullOutPath& path, const std::vector<Object>& objects) {
  std::vector<Obstacle> obstacles;
  for (const auto& o : objects) obstacles.push_back({o.id, object_polygon(o)});
  const ObjectChecker checker(vehicle_footprint(VehicleInfo{}), obstacles);
  double best = std::numeric_limits<double>::infinity();
  for (const auto& seg : path.partial_paths) {
    for (const auto& pt : seg.points) {
      best = std::min(best, checker.clearance(pt.pose).distance);
      if (std::hypot(pt.pose.x - path.end_pose.x, pt.pose.y - path.end_pose.y) < 1e-9) return best;
    }
  }
  return best;
}

void expect_same_path(const PullOutPath& a, const PullOutPath& b) {
  ASSERT_EQ(a.partial_paths.size(), b.partial_paths.size());
  for (std::size_t i = 0; i < a.partial_paths.size(); ++i) {
    const auto& pa = a.partial_paths[i].points;
    const auto& pb = b.partial_paths[i].points;
    ASSERT_EQ(pa.size(), pb.size());
    for (std::size_t j = 0; j < pa.size(); ++j) {
      EXPECT_EQ(pa[j].pose.x, pb[j].pose.x);
      EXPECT_EQ(pa[j].pose.y, pb[j].pose.y);
      EXPECT_EQ(pa[j].pose.yaw, pb[j].pose.yaw);
      EXPECT_EQ(pa[j].longitudinal_velocity_mps, pb[j].longitudinal_velocity_mps);
      EXPECT_EQ(pa[j].lane_ids, pb[j].lane_ids);
    }
  }
}

TEST(StartPlannerWorldReuse, TheSameLanesReuseThePreviousLaneWorldAndPlanTheSamePath) {
  const PullOutRequest first = test::straight_shoulder_request();
  const PlanningResult r1 = default_planner().plan(first, StopCondition());
  ASSERT_EQ(r1.outcome, PlanningResult::Outcome::kFound) << r1.stop_reason;
  ASSERT_TRUE(r1.world && r1.world->lane_world);

  // The vehicle's next request: moved a little, the same lanes (a copy, not the same vector).
  PullOutRequest next = first;
  next.request_id = 2;
  next.ego_pose.x = 12.5;
  const PlanningResult reused = default_planner().plan(next, StopCondition(), r1.world.get());
  const PlanningResult fresh = default_planner().plan(next, StopCondition());
  ASSERT_EQ(reused.outcome, PlanningResult::Outcome::kFound) << reused.stop_reason;
  ASSERT_EQ(fresh.outcome, PlanningResult::Outcome::kFound) << fresh.stop_reason;
  EXPECT_EQ(reused.world->lane_world, r1.world->lane_world);
  EXPECT_NE(fresh.world->lane_world, r1.world->lane_world);
  expect_same_path(reused.path, fresh.path);
  ASSERT_EQ(reused.evaluation_table.size(), fresh.evaluation_table.size());
  for (std::size_t i = 0; i < reused.evaluation_table.size(); ++i) {
    EXPECT_EQ(reused.evaluation_table[i].outcome, fresh.evaluation_table[i].outcome);
    EXPECT_EQ(reused.evaluation_table[i].detail, fresh.evaluation_table[i].detail);
  }
}

TEST(StartPlannerWorldReuse, OtherLanesOrAnIncompleteWorldBuildAFreshOne) {
  const PullOutRequest first = test::straight_shoulder_request();
  const PlanningResult r1 = default_planner().plan(first, StopCondition());
  ASSERT_TRUE(r1.world && r1.world->lane_world);

  // The shoulder 10 cm wider: another world, and the path planned on it.
  PullOutRequest wider = first;
  wider.lanes[1].right_bound.front().y += 0.1;
  wider.lanes[1].right_bound.back().y += 0.1;
  const PlanningResult r2 = default_planner().plan(wider, StopCondition(), r1.world.get());
  ASSERT_TRUE(r2.world && r2.world->lane_world);
  EXPECT_NE(r2.world->lane_world, r1.world->lane_world);
  EXPECT_EQ(r2.world->lane_world->lanes()[1].polygon, LaneWorld(wider.lanes).lanes()[1].polygon);

  // A build cut short keeps no lane world to offer.
  std::atomic<bool> cancel{true};
  const PlanningResult stopped = default_planner().plan(first, StopCondition().with_cancel(&cancel));
  ASSERT_EQ(stopped.stopped, StopReason::kCancelled);
  ASSERT_TRUE(stopped.world);
  EXPECT_EQ(stopped.world->lane_world, nullptr);
  const PlanningResult after = default_planner().plan(first, StopCondition(), stopped.world.get());
  ASSERT_EQ(after.outcome, PlanningResult::Outcome::kFound) << after.stop_reason;
  EXPECT_NE(after.world->lane_world, nullptr);
}

TEST(StartPlanner, ParkedCarAheadForcesASmallerMargin) {
  auto req = test::straight_shoulder_request();
  req.objects.push_back(test::parked_car(7, 24.0, 3.25));
  const PlanningResult r = shift_only_planner().plan(req, StopCondition());
  ASSERT_EQ(r.outcome, PlanningResult::Outcome::kFound) << r.stop_reason;
  // Every larger margin was tried first and failed for the car.
  ASSERT_GE(r.evaluation_table.size(), 2u);
  for (std::size_t i = 0; i + 1 < r.evaluation_table.size(); ++i) {
    EXPECT_EQ(r.evaluation_table[i].outcome, AttemptOutcome::kCollision);
    EXPECT_NE(r.evaluation_table[i].detail.find("object 7"), std::string::npos) << r.evaluation_table[i].detail;
  }
  const PlannerAttempt& winner = r.evaluation_table.back();
  EXPECT_EQ(winner.outcome, AttemptOutcome::kSuccess);
  EXPECT_LT(winner.margin_m, 2.0);
  // The path never touches the car (independent check over the whole path to the end pose).
  EXPECT_GT(min_clearance(r.path, req.objects), 0.0);
}

TEST(StartPlanner, BoxedInGivesAStopPathWithEveryAttemptsReason) {
  auto req = test::straight_shoulder_request();
  req.objects.push_back(test::parked_car(7, 16.5, 3.25));  // 0.46 m ahead of the bumper
  req.objects.push_back(test::parked_car(8, 5.0, 3.25));   // behind
  const PlanningResult r = shift_only_planner().plan(req, StopCondition());
  ASSERT_EQ(r.outcome, PlanningResult::Outcome::kNoPath);
  EXPECT_FALSE(r.path.found);
  EXPECT_EQ(r.path.planner_type, PlannerType::kStop);
  ASSERT_EQ(r.path.partial_paths.size(), 1u);
  EXPECT_EQ(r.path.pairs_terminal_velocity_and_accel.size(), 1u);
  for (const auto& pt : r.path.partial_paths[0].points) {
    EXPECT_DOUBLE_EQ(pt.longitudinal_velocity_mps, 0.0);
    EXPECT_DOUBLE_EQ(pt.pose.x, req.ego_pose.x);
  }
  EXPECT_EQ(r.evaluation_table.size(), StartPlannerParameters{}.collision_check_margins.size());
  for (const auto& a : r.evaluation_table) EXPECT_EQ(a.outcome, AttemptOutcome::kCollision) << describe(a);
  ASSERT_FALSE(r.path.reasons.empty());
  EXPECT_NE(r.path.reasons[0].find("margin 0.10"), std::string::npos) << r.path.reasons[0];
  EXPECT_FALSE(r.stop_reason.empty());
}

// The largest heading change [rad] between consecutive points of a path, per metre between them:
// a path a car can drive turns no faster than 1 / its full-steer radius.
double sharpest_turn(const PullOutPath& path) {
  double sharpest = 0.0;
  for (const PathWithLaneId& seg : path.partial_paths) {
    for (std::size_t i = 1; i < seg.points.size(); ++i) {
      const Pose2& a = seg.points[i - 1].pose;
      const Pose2& b = seg.points[i].pose;
      const double d = std::hypot(b.x - a.x, b.y - a.y);
      if (d > 1e-6) sharpest = std::max(sharpest, std::abs(normalize_angle(b.yaw - a.yaw)) / d);
    }
  }
  return sharpest;
}

// A vehicle standing across its lane (80 degrees off it) got a reverse "along the lane" to a start
// candidate behind it: its heading jumped 80 degrees within the first metre, a path no car can
// drive. The candidates behind are skipped then, saying why; a vehicle 10 degrees off keeps them.
TEST(StartPlanner, AVehicleAcrossItsLaneGetsNoReverseItCannotDrive) {
  const VehicleInfo vehicle;
  const double full_steer_curvature = 1.0 / vehicle.min_turning_radius_m();
  for (const double yaw_deg : {-80.0, -45.0, 90.0}) {
    auto req = test::straight_shoulder_request();
    req.ego_pose.yaw = yaw_deg * kDegToRad;
    const PlanningResult r = default_planner().plan(req, StopCondition());
    if (r.outcome == PlanningResult::Outcome::kFound) {
      EXPECT_LE(sharpest_turn(r.path), full_steer_curvature * 1.001) << yaw_deg << " deg: " << r.stop_reason;
    }
    bool skipped = false;
    for (const PlannerAttempt& a : r.evaluation_table) {
      skipped = skipped || a.detail.find("start candidates behind skipped: the vehicle's heading deviates") == 0;
    }
    EXPECT_TRUE(skipped) << yaw_deg;
  }
  auto aligned = test::straight_shoulder_request();
  aligned.ego_pose.yaw = -10.0 * kDegToRad;
  const PlanningResult r = default_planner().plan(aligned, StopCondition());
  ASSERT_EQ(r.outcome, PlanningResult::Outcome::kFound) << r.stop_reason;
  EXPECT_LE(sharpest_turn(r.path), full_steer_curvature * 1.001);
  for (const PlannerAttempt& a : r.evaluation_table) {
    EXPECT_EQ(a.detail.find("start candidates behind skipped"), std::string::npos) << a.detail;
  }
}

TEST(StartPlanner, MovingObjectsAreNotStaticObstacles) {
  auto req = test::straight_shoulder_request();
  Object passing = test::parked_car(7, 16.5, 3.25);
  passing.velocity_mps = 5.0;
  req.objects.push_back(passing);
  EXPECT_EQ(default_planner().plan(req, StopCondition()).outcome, PlanningResult::Outcome::kFound);
}

TEST(StartPlanner, ExpiredDeadlineEndsTheSearchWithTimeout) {
  auto req = test::straight_shoulder_request();
  const PlanningResult r = default_planner().plan(req, StopCondition::after_ms(0.0));
  EXPECT_EQ(r.outcome, PlanningResult::Outcome::kNoPath);
  EXPECT_TRUE(r.timed_out);
  EXPECT_EQ(r.stopped, StopReason::kDeadline);
  EXPECT_NE(r.stop_reason.find("deadline"), std::string::npos);
  EXPECT_FALSE(r.path.found);
}

// Typed outcomes on the shared scenario files: each row's outcome is a value, the detail says
// which object (or which limit).
Scenario load(const std::string& name) {
  return load_scenario(std::string(PULLOUT_SOURCE_DIR) + "/tests/scenarios/" + name + ".yaml");
}

TEST(StartPlannerOutcomes, CollisionRowsNameTheObject) {
  const Scenario sc = load("parked_car_ahead");
  const PlanningResult r = StartPlanner(sc.vehicle, sc.parameters).plan(sc.request, StopCondition());
  ASSERT_EQ(r.outcome, PlanningResult::Outcome::kFound) << r.stop_reason;
  ASSERT_GE(r.evaluation_table.size(), 2u);
  for (std::size_t i = 0; i + 1 < r.evaluation_table.size(); ++i) {
    const PlannerAttempt& a = r.evaluation_table[i];
    EXPECT_EQ(a.outcome, AttemptOutcome::kCollision) << describe(a);
    EXPECT_NE(a.detail.find("object 7"), std::string::npos) << a.detail;
  }
  EXPECT_EQ(r.evaluation_table.back().outcome, AttemptOutcome::kSuccess);
}

TEST(StartPlannerOutcomes, LaneDepartureRows) {
  Scenario sc = load("straight_shoulder");
  sc.parameters.enable_back = false;
  sc.parameters.freespace_planner.enable_freespace_planner = false;
  // A departure check footprint 3 m wider on each side than the car leaves any lane.
  sc.parameters.lane_departure_check_expansion_margin = 3.0;
  sc.parameters.lane_departure_margin = 3.0;  // the geometric planner's
  sc.parameters.allow_check_shift_path_lane_departure_override = false;
  const PlanningResult r = StartPlanner(sc.vehicle, sc.parameters).plan(sc.request, StopCondition());
  EXPECT_EQ(r.outcome, PlanningResult::Outcome::kNoPath);
  ASSERT_FALSE(r.evaluation_table.empty());
  for (const PlannerAttempt& a : r.evaluation_table) {
    EXPECT_EQ(a.outcome, AttemptOutcome::kLaneDeparture) << to_string(a.planner) << ": " << describe(a);
  }
  ASSERT_FALSE(r.path.reasons.empty());
  EXPECT_NE(r.path.reasons[0].find("lane_departure"), std::string::npos) << r.path.reasons[0];
}

TEST(StartPlannerOutcomes, BoxedInStartCandidateIsStartInvalid) {
  const Scenario sc = load("boxed_in");
  const PlanningResult r = StartPlanner(sc.vehicle, sc.parameters).plan(sc.request, StopCondition());
  ASSERT_EQ(r.outcome, PlanningResult::Outcome::kNoPath);
  ASSERT_FALSE(r.evaluation_table.empty());
  // The start-candidate rows come first: the pose just clear of car 8 behind (skipped, car 7
  // ahead is too close), then the end of the backward search at car 8.
  bool search_ended_at_8 = false;
  for (const PlannerAttempt& a : r.evaluation_table) {
    if (a.planner != PlannerType::kNone) break;
    EXPECT_EQ(a.outcome, AttemptOutcome::kStartInvalid) << a.detail;
    search_ended_at_8 = search_ended_at_8 || (a.detail.find("object 8") != std::string::npos &&
                                              a.detail.find("backward search ends") != std::string::npos);
  }
  EXPECT_EQ(r.evaluation_table[0].planner, PlannerType::kNone);
  EXPECT_TRUE(search_ended_at_8);
}

TEST(StartPlannerOutcomes, FreespaceTimeLimitGivesATimeoutRow) {
  Scenario sc = load("freespace_boxed_in");
  sc.parameters.freespace_planner.time_limit = 0.0;
  const PlanningResult r = StartPlanner(sc.vehicle, sc.parameters).plan(sc.request, StopCondition());
  ASSERT_FALSE(r.evaluation_table.empty());
  EXPECT_EQ(r.evaluation_table.back().planner, PlannerType::kFreespace);
  EXPECT_EQ(r.evaluation_table.back().outcome, AttemptOutcome::kTimeout);
  EXPECT_FALSE(r.timed_out);  // the planner's budget, not the planning deadline
}

TEST(StartPlannerOutcomes, CancelledSearchGivesACancelledRow) {
  const Scenario sc = load("freespace_parking_lot");  // grid only: one freespace search
  std::atomic<bool> cancel{true};
  const PlanningResult r =
      StartPlanner(sc.vehicle, sc.parameters).plan(sc.request, StopCondition().with_cancel(&cancel));
  EXPECT_EQ(r.outcome, PlanningResult::Outcome::kNoPath);
  EXPECT_EQ(r.stopped, StopReason::kCancelled);
  ASSERT_EQ(r.evaluation_table.size(), 1u);
  EXPECT_EQ(r.evaluation_table[0].outcome, AttemptOutcome::kCancelled);
}

// A grid-only request whose start or goal the search refuses says which and why: outside the
// grid, or the vehicle there meets an obstacle (the row said only "to the goal").
TEST(StartPlannerOutcomes, ARefusedStartOrGoalOfAGridSaysWhichAndWhy) {
  const Scenario sc = load("freespace_parking_lot");  // grid only, 30 m x 30 m from the origin
  const StartPlanner planner(sc.vehicle, sc.parameters);
  const auto detail_of = [&](const Pose2& start, const Pose2& goal) {
    PullOutRequest request = sc.request;
    request.ego_pose = start;
    request.goal_pose = goal;
    const PlanningResult r = planner.plan(request, StopCondition());
    EXPECT_EQ(r.outcome, PlanningResult::Outcome::kNoPath);
    return r.evaluation_table.empty() ? std::string() : r.evaluation_table.back().detail;
  };
  // The start on the first parked car of the lower row (x 3, y 3).
  EXPECT_EQ(detail_of({3.0, 3.0, kPi / 2}, sc.request.goal_pose),
            "the start (x 3.00, y 3.00): the vehicle there meets an obstacle or the grid's edge");
  EXPECT_EQ(detail_of(sc.request.ego_pose, {40.0, 26.0, 0.0}), "the goal (x 40.00, y 26.00) lies outside the grid");
}

TEST(StartPlannerOutcomes, CancelledLaneSearchStopsBeforeTheFirstAttempt) {
  const Scenario sc = load("straight_shoulder");
  std::atomic<bool> cancel{true};
  const PlanningResult r =
      StartPlanner(sc.vehicle, sc.parameters).plan(sc.request, StopCondition().with_cancel(&cancel));
  EXPECT_EQ(r.outcome, PlanningResult::Outcome::kNoPath);
  EXPECT_EQ(r.stopped, StopReason::kCancelled);
  EXPECT_FALSE(r.timed_out);
  EXPECT_TRUE(r.evaluation_table.empty());
  EXPECT_NE(r.stop_reason.find("cancelled"), std::string::npos) << r.stop_reason;
}

TEST(StartPlanner, SearchPolicyOverrideAndUnavailablePlanner) {
  auto req = test::straight_shoulder_request();
  req.overrides.search_priority = {PlannerType::kStop};  // not a planner that can be searched
  const PlanningResult r = default_planner().plan(req, StopCondition());
  EXPECT_EQ(r.outcome, PlanningResult::Outcome::kRejected);
  EXPECT_TRUE(has_issue(r, "overrides.search_priority[0]"));
}

TEST(StartPlannerValidation, NonFiniteValuesNameTheField) {
  auto req = test::straight_shoulder_request();
  req.ego_pose.x = std::numeric_limits<double>::quiet_NaN();
  req.goal_pose.yaw = std::numeric_limits<double>::infinity();
  req.lanes[1].left_bound[1].y = std::numeric_limits<double>::quiet_NaN();
  const PlanningResult r = default_planner().plan(req, StopCondition());
  EXPECT_EQ(r.outcome, PlanningResult::Outcome::kRejected);
  EXPECT_TRUE(has_issue(r, "ego_pose.x"));
  EXPECT_TRUE(has_issue(r, "goal_pose.yaw"));
  EXPECT_TRUE(has_issue(r, "lanes[1].left_bound[1]"));
  EXPECT_NE(format_issues(r.issues).find("ego_pose.x: not a finite number (NaN)"), std::string::npos);
}

TEST(StartPlannerValidation, EmptyAndDegenerateLanes) {
  auto req = test::straight_shoulder_request();
  req.lanes.clear();
  EXPECT_TRUE(has_issue(default_planner().plan(req, StopCondition()), "lanes"));

  req = test::straight_shoulder_request();
  req.lanes[0].right_bound = req.lanes[0].left_bound;  // zero area
  req.lanes[1].left_bound.resize(1);
  const PlanningResult r = default_planner().plan(req, StopCondition());
  EXPECT_TRUE(has_issue(r, "lanes[0]"));
  EXPECT_TRUE(has_issue(r, "lanes[1].left_bound"));

  req = test::straight_shoulder_request();
  req.lanes[0].subtype = LaneSubtype::kRoadShoulder;
  EXPECT_TRUE(has_issue(default_planner().plan(req, StopCondition()), "lanes"));

  req = test::straight_shoulder_request();
  req.lanes[1].id = req.lanes[0].id;
  EXPECT_TRUE(has_issue(default_planner().plan(req, StopCondition()), "lanes[1].id"));
}

TEST(StartPlannerValidation, StartPoseOffTheLanes) {
  auto req = test::straight_shoulder_request();
  req.ego_pose = {50.0, 40.0, 0.0};
  const PlanningResult r = default_planner().plan(req, StopCondition());
  EXPECT_EQ(r.outcome, PlanningResult::Outcome::kRejected);
  ASSERT_TRUE(has_issue(r, "ego_pose"));
  EXPECT_NE(format_issues(r.issues).find("on no lane"), std::string::npos);
}

TEST(StartPlannerValidation, SizeLimits) {
  RequestLimits limits;
  limits.max_objects = 2;
  limits.max_points_per_line = 10;
  const StartPlanner planner(VehicleInfo{}, StartPlannerParameters{}, limits);
  auto req = test::straight_shoulder_request();
  for (int i = 0; i < 3; ++i) req.objects.push_back(test::parked_car(i, 60.0 + 6 * i, 3.25));
  req.lanes[0].left_bound.resize(11, {100.0, 1.75});
  const auto issues = planner.validate(req);
  const std::string text = format_issues(issues);
  EXPECT_NE(text.find("objects: 3 objects exceed the limit of 2"), std::string::npos) << text;
  EXPECT_NE(text.find("lanes[0].left_bound: 11 points exceed the limit of 10"), std::string::npos) << text;
}

// The generated DDS key buffer holds kMaxVehicleIdBytes bytes: a longer id could not be answered.
TEST(StartPlannerValidation, VehicleIdLongerThanTheKeyBufferIsRejected) {
  auto req = test::straight_shoulder_request();
  req.vehicle_id = std::string(kMaxVehicleIdBytes, 'v');
  auto issues = default_planner().validate(req);
  EXPECT_TRUE(issues.empty()) << format_issues(issues);

  req.vehicle_id = std::string(256, 'v');
  issues = default_planner().validate(req);
  ASSERT_EQ(issues.size(), 1u) << format_issues(issues);
  EXPECT_EQ(issues[0].field, "vehicle_id");
  EXPECT_NE(issues[0].problem.find("longer than 255 bytes"), std::string::npos) << format_issues(issues);
}

TEST(StartPlannerValidation, RouteWithoutMapAndBadDeadline) {
  auto req = test::straight_shoulder_request();
  req.route_lanelet_ids = {4618};
  req.deadline_ms = -5.0;
  const PlanningResult r = default_planner().plan(req, StopCondition());
  EXPECT_TRUE(has_issue(r, "route_lanelet_ids"));
  EXPECT_TRUE(has_issue(r, "deadline_ms"));
}

TEST(StartPlanner, ReversingMovesBackwardsWhenTheVehicleFacesAgainstItsLane) {
  // The shoulder is drawn westwards (its bounds run from x = 100 to 0) while the vehicle faces
  // east, as a car parked against the shoulder's direction. A car close ahead makes it reverse:
  // the reverse leg must go west (behind the vehicle), not east along the lane's direction.
  auto req = test::straight_shoulder_request();
  Lane& shoulder = req.lanes[1];
  shoulder.left_bound = {{100.0, 1.75}, {-30.0, 1.75}};
  shoulder.right_bound = {{100.0, 4.75}, {-30.0, 4.75}};
  req.objects.push_back(test::parked_car(7, 19.04, 3.25));  // 3 m ahead of the bumper
  StartPlannerParameters p;
  p.search_priority = {PlannerType::kShift};
  const PlanningResult r = StartPlanner(VehicleInfo{}, p).plan(req, StopCondition());
  ASSERT_EQ(r.outcome, PlanningResult::Outcome::kFound) << r.stop_reason;
  ASSERT_GE(r.path.partial_paths.size(), 2u);
  const auto& reverse = r.path.partial_paths[0].points;
  EXPECT_LT(reverse.front().longitudinal_velocity_mps, 0.0);
  EXPECT_LT(reverse.back().pose.x, reverse.front().pose.x - 1.0) << "the reverse leg goes behind the vehicle";
  for (const auto& pt : reverse) EXPECT_NEAR(std::cos(pt.pose.yaw), 1.0, 1e-6) << "the vehicle keeps facing east";
}

}  // namespace
}  // namespace pullout
