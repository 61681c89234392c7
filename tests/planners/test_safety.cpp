// The dynamic-object safety check with hand-computed numbers: RSS distances, the ego prediction,
// the jerk-limited stop, the lateral threshold, and the rear-vehicle "preventing" bypass.
#include <gtest/gtest.h>

#include <cmath>

#include "pullout/config/scenario.hpp"
#include "pullout/geometry/angle.hpp"
#include "pullout/pipeline/start_planner.hpp"
#include "pullout/safety/rss_check.hpp"
#include "pullout/safety/safety_monitor.hpp"
#include "pullout/safety/stop_path.hpp"
#include "pullout/search/stop_condition.hpp"
#include "test_world.hpp"

namespace pullout {
namespace {

Object car(std::int64_t id, double x, double y, double v, double yaw = 0.0) {
  Object o;
  o.id = id;
  o.object_class = ObjectClass::kCar;
  o.pose = {x, y, yaw};
  o.length_m = 4.5;
  o.width_m = 1.9;
  o.velocity_mps = v;
  return o;
}

Polyline x_axis() { return Polyline({{0.0, 0.0}, {100.0, 0.0}}); }

TEST(RssDistance, FormulaWithDefaults) {
  const RssParameters p;  // t_react 2 s, t_margin 1 s, b = -1 m/s^2
  // Rear at 10 m/s behind a standing front: 10 * 3 + 100 / 2 = 80 m.
  EXPECT_DOUBLE_EQ(rss_distance(0.0, 10.0, p), 80.0);
  // Same speeds: the braking terms cancel, 10 * 3 = 30 m.
  EXPECT_DOUBLE_EQ(rss_distance(10.0, 10.0, p), 30.0);
  // Front much faster: 1 * 3 + 0.5 - 12.5 = -9 m, so the minimum 0.8 * 5 + 3 = 7 m applies.
  EXPECT_DOUBLE_EQ(rss_distance(5.0, 1.0, p), -9.0);
  EXPECT_DOUBLE_EQ(rss_longitudinal_offset(5.0, 1.0, 1.0, 5.0, p), 7.0);
}

TEST(EgoPrediction, WaitsThenAcceleratesToTheTerminalVelocity) {
  const EgoPredictedPathParameters p;  // delay 1 s, step 0.5 s, horizons 10 s
  const auto path = predict_ego_motion(x_axis(), {10.0, 0.0, 0.0}, 0.0, 2.0, 1.0, p);
  ASSERT_EQ(path.size(), 20u);              // t = 0, 0.5, ..., 9.5
  EXPECT_DOUBLE_EQ(path[1].pose.x, 10.0);   // t = 0.5: still waiting
  EXPECT_DOUBLE_EQ(path[2].pose.x, 10.0);   // t = 1.0: departs now
  EXPECT_NEAR(path[4].pose.x, 10.5, 1e-9);  // t = 2: 0.5 * 1 * 1^2
  EXPECT_NEAR(path[4].velocity, 1.0, 1e-9);
  EXPECT_NEAR(path[6].pose.x, 12.0, 1e-9);  // t = 3: reaches 2 m/s after 2 m
  EXPECT_NEAR(path[8].pose.x, 14.0, 1e-9);  // t = 4: then 2 m/s (not 0.5 * 1 * 3^2 = 4.5 m)
  EXPECT_NEAR(path[8].velocity, 2.0, 1e-9);
}

TEST(StopProfile, JerkLimitedDistance) {
  // From 2 m/s: the deceleration ramps to 1 m/s^2 in 1 s (2 - 1/6 m, speed 1.5 m/s), then
  // 1.5^2 / 2 = 1.125 m: 2.9583 m in all.
  const StopProfile stop(2.0, 1.0, 1.0);
  EXPECT_NEAR(stop.distance(), 2.0 - 1.0 / 6.0 + 1.125, 2e-3);
  EXPECT_DOUBLE_EQ(stop.velocity_at(0.0), 2.0);
  EXPECT_DOUBLE_EQ(stop.velocity_at(3.0), 0.0);
  // From 0.5 m/s the ramp alone stops it: v = 0.5 - t^2 / 2 reaches 0 at t = 1, after 1/3 m.
  EXPECT_NEAR(StopProfile(0.5, 1.0, 1.0).distance(), 1.0 / 3.0, 2e-3);
  EXPECT_DOUBLE_EQ(StopProfile(0.0, 1.0, 1.0).distance(), 0.0);
}

class RssCheck : public ::testing::Test {
 protected:
  RssVerdict check(const Object& object) const {
    const auto ego = predict_ego_motion(x_axis(), {10.0, 0.0, 0.0}, 0.0, 2.0, 1.0, EgoPredictedPathParameters{});
    return check_rss(ego, vehicle_footprint(VehicleInfo{}), {object}, TargetFilteringParameters{}, SafetyCheckParams{},
                     1.0);
  }
};

TEST_F(RssCheck, FastCarFromBehindIsUnsafe) {
  // At t = 0 the car's front (-30 + 2.25) extended by 80 m reaches 52.25 m > the ego's rear (8.9).
  const RssVerdict v = check(car(7, -30.0, 0.0, 10.0));
  EXPECT_FALSE(v.safe);
  EXPECT_EQ(v.object_id, 7);
  EXPECT_DOUBLE_EQ(v.time_s, 0.0);
  EXPECT_NE(v.reason.find("rear"), std::string::npos) << v.reason;
}

TEST_F(RssCheck, FarCarIsSafe) {
  // Its extended front stays behind the ego: -197.75 + 80 at t = 0, -97.75 + 78 at t = 10 s.
  EXPECT_TRUE(check(car(7, -200.0, 0.0, 10.0)).safe);
}

TEST_F(RssCheck, SlowCarAheadIsUnsafeOnceTheEgoCatchesUp) {
  // Car ahead at 0.5 m/s, rear at 25 - 2.25 = 22.75 m. At t = 0 the ego's front (13.79) plus
  // d_min (0.8 * 0.5 + 3 = 3.4) stays short of it; at t = 4 s the ego is at 14 m doing 2 m/s:
  // d_rss = 2 * 3 + 2 - 0.125 = 7.875, 17.79 + 7.875 = 25.67 > 24.75 (the car has moved 2 m).
  const RssVerdict v = check(car(8, 25.0, 0.0, 0.5));
  EXPECT_FALSE(v.safe);
  EXPECT_GT(v.time_s, 0.0);
  EXPECT_LE(v.time_s, 4.0);
  EXPECT_NE(v.reason.find("front"), std::string::npos) << v.reason;
}

TEST_F(RssCheck, LateralThreshold) {
  // Rear car (extended 80 m forward) beside the ego: unsafe while its side, grown by 2 m,
  // reaches the ego's side: y - 0.95 - 2.0 <= 0.948, i.e. y <= 3.898 m.
  EXPECT_FALSE(check(car(1, 0.0, 3.85, 10.0)).safe);
  EXPECT_TRUE(check(car(2, 0.0, 3.95, 10.0)).safe);
}

TEST_F(RssCheck, OncomingObjectsAreSkipped) {
  // Heading differs by pi > 1.578 rad: not checked (oncoming traffic is another lane's business).
  EXPECT_TRUE(check(car(3, 40.0, 3.0, 10.0, kPi)).safe);
}

TEST_F(RssCheck, PredictedPathIsFollowed) {
  // Standing now, but its prediction jumps into the ego's lane behind it at speed.
  Object o = car(4, -30.0, 8.0, 10.0);
  PredictedPath away;
  away.time_step_s = 1.0;
  for (int i = 0; i <= 10; ++i) away.poses.push_back({-30.0 + 10.0 * i, 8.0, 0.0});
  o.predicted_paths = {away};
  EXPECT_TRUE(check(o).safe);  // stays 8 m to the left
  PredictedPath merging = away;
  for (auto& pose : merging.poses) pose.y = 0.0;
  o.predicted_paths.push_back(merging);
  EXPECT_FALSE(check(o).safe);  // use_all_predicted_path: the merging one counts
}

TEST(MovingObjectAround, RadiusAndSpeed) {
  const SurroundMovingObstacleCheckParameters p;  // 10 m, 1 m/s
  Object walker = car(5, 15.0, 5.0, 1.5);
  walker.object_class = ObjectClass::kPedestrian;
  EXPECT_EQ(moving_object_around({10.0, 0.0, 0.0}, {walker}, p), std::optional<std::int64_t>(5));
  walker.velocity_mps = 0.9;
  EXPECT_FALSE(moving_object_around({10.0, 0.0, 0.0}, {walker}, p));
  walker.velocity_mps = 1.5;
  walker.pose.x = 30.0;  // 20.6 m away
  EXPECT_FALSE(moving_object_around({10.0, 0.0, 0.0}, {walker}, p));
}

// A straight forward path along y = `y` on the straight-shoulder world (road y in [-1.75, 1.75],
// shoulder on its left).
PullOutPath straight_path(double y, double velocity = 2.0) {
  PullOutPath path;
  path.found = true;
  PathWithLaneId segment;
  for (int x = 0; x <= 100; x += 2) segment.points.push_back({{static_cast<double>(x), y, 0.0}, velocity, {1}});
  path.partial_paths = {segment};
  path.pairs_terminal_velocity_and_accel = {{2.0, 1.0}};
  path.start_pose = {0.0, y, 0.0};
  path.end_pose = {100.0, y, 0.0};
  return path;
}

// The straight-shoulder world lengthened backwards, so that traffic behind the ego is on a lane.
std::vector<Lane> long_lanes() {
  return {test::straight_lane(1, LaneSubtype::kRoad, -200, 100, -1.75, 1.75),
          test::straight_lane(2, LaneSubtype::kRoadShoulder, -200, 100, 1.75, 4.75)};
}

SafetyMonitor monitor(std::vector<Object> objects, const PullOutPath& path, StartPlannerParameters p = {}) {
  return SafetyMonitor(p, VehicleInfo{}, long_lanes(), std::move(objects), path);
}

TEST(PreventingRearVehicle, GapToThePassingSideBound) {
  const std::vector<Object> rear = {car(1, 0.0, 0.0, 10.0)};
  // On the shoulder (right corners at y = 2.302): 4.052 m to the road's right bound, wide enough
  // for the rear car (1.9 + 0.5 m).
  EXPECT_FALSE(monitor(rear, straight_path(3.25)).preventing_rear_vehicle({{20.0, 3.25, 0.0}}));
  // At y = 1.0 the gap is 1.802 m (< 2.4, > 1.698 to the left bound): the car could not pass.
  EXPECT_TRUE(monitor(rear, straight_path(1.0)).preventing_rear_vehicle({{20.0, 1.0, 0.0}}));
  // A car 1.0 m wide could (1.5 <= 1.802).
  std::vector<Object> narrow = rear;
  narrow[0].width_m = 1.0;
  EXPECT_FALSE(monitor(narrow, straight_path(1.0)).preventing_rear_vehicle({{20.0, 1.0, 0.0}}));
  // Nobody behind: nothing to prevent.
  EXPECT_FALSE(monitor({}, straight_path(1.0)).preventing_rear_vehicle({{20.0, 1.0, 0.0}}));
  // At y = 0.5 the ego is over the middle (1.302 <= 2.198): preventing whoever comes.
  EXPECT_TRUE(monitor({}, straight_path(0.5)).preventing_rear_vehicle({{20.0, 0.5, 0.0}}));
  // The estimated stop pose counts too.
  EXPECT_TRUE(monitor({}, straight_path(3.25)).preventing_rear_vehicle({{20.0, 3.25, 0.0}, {25.0, 0.5, 0.0}}));
}

TEST(PreventingRearVehicle, TheNearestCarBehindAndItsWidthDecide) {
  // The ego at y = 1.0 leaves 1.802 m to the road's right bound (see above); margin 0.5 m.
  Object wide = car(1, 0.0, 0.0, 10.0);  // 1.9 + 0.5 > 1.802: could not pass
  Object narrow = car(2, 0.0, 0.0, 10.0);
  narrow.width_m = 1.0;  // 1.5 <= 1.802: could pass
  const PullOutPath path = straight_path(1.0);
  const std::vector<Pose2> at = {{20.0, 1.0, 0.0}};
  // Only the nearest car behind counts: the other one is farther back.
  wide.pose.x = 10.0;
  narrow.pose.x = -10.0;
  EXPECT_TRUE(monitor({narrow, wide}, path).preventing_rear_vehicle(at));
  wide.pose.x = -10.0;
  narrow.pose.x = 10.0;
  EXPECT_FALSE(monitor({wide, narrow}, path).preventing_rear_vehicle(at));
  // A footprint polygon (object frame) gives the width instead of width_m: 2.4 m across.
  Object shaped = narrow;
  shaped.polygon = {{-2.0, -1.2}, {2.0, -1.2}, {2.0, 1.2}, {-2.0, 1.2}};
  EXPECT_TRUE(monitor({shaped}, path).preventing_rear_vehicle(at));
  // 0.8 m across although width_m says 3.0.
  shaped.width_m = 3.0;
  shaped.polygon = {{-2.0, -0.4}, {2.0, -0.4}, {2.0, 0.4}, {-2.0, 0.4}};
  EXPECT_FALSE(monitor({shaped}, path).preventing_rear_vehicle(at));
}

TEST(SafetyMonitor, HoldsForAFastCarFromBehind) {
  auto m = monitor({car(1, -20.0, 0.0, 10.0)}, straight_path(3.25));
  const SafetyVerdict v = m.evaluate({10.0, 3.25, 0.0}, 0.0, 0, false);
  EXPECT_FALSE(v.safe);
  EXPECT_TRUE(v.rss_checked);
  EXPECT_EQ(v.object_id, 1);
  EXPECT_EQ(v.reason.rfind("dynamic object risk", 0), 0u) << v.reason;
}

TEST(SafetyMonitor, FarOrFilteredCarsAreSafe) {
  // 90 m behind at 5 m/s: extended front at -77.75 + 27.5 m, far behind the ego.
  EXPECT_TRUE(monitor({car(1, -80.0, 0.0, 5.0)}, straight_path(3.25)).evaluate({10.0, 3.25, 0.0}, 0.0, 0, false).safe);
  // More than object_check_backward_distance (100 m) behind: not a target.
  EXPECT_TRUE(monitor({car(1, -95.0, 0.0, 30.0)}, straight_path(3.25)).evaluate({10.0, 3.25, 0.0}, 0.0, 0, false).safe);
  // Slower than ignore_object_velocity_threshold: not a target.
  EXPECT_TRUE(monitor({car(1, -5.0, 0.0, 0.2)}, straight_path(3.25)).evaluate({10.0, 3.25, 0.0}, 0.0, 0, false).safe);
}

TEST(SafetyMonitor, CarThatCouldNotPassDoesNotHold) {
  const std::vector<Object> rear = {car(1, -10.0, 0.0, 10.0)};
  const SafetyVerdict v = monitor(rear, straight_path(1.0)).evaluate({10.0, 1.0, 0.0}, 0.0, 0, true);
  EXPECT_TRUE(v.safe);
  EXPECT_TRUE(v.preventing_rear);
  EXPECT_FALSE(v.rss_checked);
  StartPlannerParameters p;
  p.skip_rear_vehicle_check = true;
  EXPECT_FALSE(monitor(rear, straight_path(1.0), p).evaluate({10.0, 1.0, 0.0}, 0.0, 0, true).safe);
}

TEST(SafetyMonitor, NearbyMovingObjectHoldsOnlyBeforeDeparture) {
  Object walker = car(5, 15.0, 5.5, 1.5);  // outside the lanes, 5.2 m from the ego
  walker.object_class = ObjectClass::kPedestrian;
  auto m = monitor({walker}, straight_path(3.25));
  const SafetyVerdict before = m.evaluate({10.0, 3.25, 0.0}, 0.0, 0, false);
  EXPECT_FALSE(before.safe);
  EXPECT_EQ(before.reason.rfind("nearby moving object risk", 0), 0u) << before.reason;
  EXPECT_TRUE(m.evaluate({10.0, 3.25, 0.0}, 1.0, 0, true).safe);
}

TEST(SafetyMonitor, NoCheckInReverse) {
  auto m = monitor({car(1, -20.0, 0.0, 10.0)}, straight_path(3.25, -1.0));
  const SafetyVerdict v = m.evaluate({10.0, 3.25, 0.0}, 0.0, 0, true);
  EXPECT_TRUE(v.safe);
  EXPECT_FALSE(v.rss_checked);
}

TEST(SafetyMonitor, PlannedShiftPathAgainstTraffic) {
  PullOutRequest request = test::straight_shoulder_request();
  request.lanes = long_lanes();
  const PlanningResult r =
      StartPlanner(VehicleInfo{}, StartPlannerParameters{}).plan(request, StopCondition::after_ms(1000));
  ASSERT_EQ(r.outcome, PlanningResult::Outcome::kFound);
  SafetyMonitor m(StartPlannerParameters{}, VehicleInfo{}, long_lanes(), {car(1, -20.0, 0.0, 10.0)}, r.path);
  EXPECT_FALSE(m.evaluate(request.ego_pose, 0.0, 0, false).safe);
  m.update_objects({car(1, -90.0, 0.0, 3.0)});
  EXPECT_TRUE(m.evaluate(request.ego_pose, 0.0, 0, false).safe);
}

}  // namespace
}  // namespace pullout

namespace pullout {
namespace {

TEST(StopPath, VelocitiesFollowTheJerkLimitedStop) {
  PullOutPath path;
  path.found = true;
  for (int k = 0; k < 2; ++k) {
    PathWithLaneId segment;
    for (int x = 0; x <= 50; ++x) segment.points.push_back({{static_cast<double>(x), 0.0, 0.0}, 3.0, {1}});
    path.partial_paths.push_back(segment);
    path.pairs_terminal_velocity_and_accel.push_back({3.0, 0.0});
  }
  // At x = 10 moving 2 m/s: stops within 2.958 m (see StopProfile), i.e. before x = 13.
  const PullOutPath stop = insert_feasible_stop(path, 0, {10.0, 0.0, 0.0}, 2.0, StopConditionParameters{});
  const auto& points = stop.partial_paths[0].points;
  EXPECT_DOUBLE_EQ(points[5].longitudinal_velocity_mps, 2.0);  // behind: capped by the current speed
  EXPECT_DOUBLE_EQ(points[10].longitudinal_velocity_mps, 2.0);
  EXPECT_GT(points[12].longitudinal_velocity_mps, 0.0);
  EXPECT_LT(points[12].longitudinal_velocity_mps, points[11].longitudinal_velocity_mps);
  EXPECT_DOUBLE_EQ(points[13].longitudinal_velocity_mps, 0.0);
  EXPECT_DOUBLE_EQ(points[50].longitudinal_velocity_mps, 0.0);
  for (const auto& q : stop.partial_paths[1].points) EXPECT_DOUBLE_EQ(q.longitudinal_velocity_mps, 0.0);
  EXPECT_DOUBLE_EQ(stop.pairs_terminal_velocity_and_accel[0].velocity_mps, 0.0);
  // Never faster than requested by the jerk-limited profile: v^2 / 2 + ... <= distance bound.
  for (std::size_t i = 11; i < 13; ++i) {
    const double d = static_cast<double>(i) - 10.0;
    EXPECT_LE(points[i].longitudinal_velocity_mps, StopProfile(2.0, 1.0, 1.0).velocity_at(d) + 1e-12);
  }
}

}  // namespace
}  // namespace pullout

namespace pullout {
namespace {

// The bundled traffic scenarios: the path is found, and the safety verdict at the start (before
// departure, approved) is what the file's `expect: {safe: ...}` says.
class TrafficScenarios : public ::testing::TestWithParam<const char*> {};

TEST_P(TrafficScenarios, SafetyVerdictMatchesTheFile) {
  const Scenario sc = load_scenario(std::string(PULLOUT_SOURCE_DIR) + "/tests/scenarios/" + GetParam() + ".yaml");
  const PlanningResult r = StartPlanner(sc.vehicle, sc.parameters, {}, sc.map).plan(sc.request, StopCondition());
  ASSERT_TRUE(r.path.found) << r.stop_reason;
  ASSERT_TRUE(sc.expect.safe.has_value());
  ASSERT_NE(r.world, nullptr);
  // The monitor sees exactly the world the path was planned on (for a route: the map's lanes).
  SafetyMonitor m(sc.parameters, sc.vehicle, r.world->lanes, r.world->objects, r.path);
  const SafetyVerdict v = m.evaluate(sc.request.ego_pose, sc.request.ego_velocity_mps, 0, false);
  EXPECT_EQ(v.safe, *sc.expect.safe) << v.reason;
}

INSTANTIATE_TEST_SUITE_P(Bundled, TrafficScenarios,
                         ::testing::Values("traffic_fast_from_behind", "traffic_far_behind", "traffic_cannot_pass",
                                           "map_traffic_fast_from_behind"));

TEST(TrafficScenarios, CannotPassIsTheBypassNotTheCheck) {
  const Scenario sc = load_scenario(std::string(PULLOUT_SOURCE_DIR) + "/tests/scenarios/traffic_cannot_pass.yaml");
  const PlanningResult r = StartPlanner(sc.vehicle, sc.parameters).plan(sc.request, StopCondition());
  ASSERT_TRUE(r.path.found);
  SafetyMonitor m(sc.parameters, sc.vehicle, sc.request.lanes, sc.request.objects, r.path);
  EXPECT_TRUE(m.evaluate(sc.request.ego_pose, 0.0, 0, false).preventing_rear);
  StartPlannerParameters strict = sc.parameters;
  strict.skip_rear_vehicle_check = true;
  SafetyMonitor s(strict, sc.vehicle, sc.request.lanes, sc.request.objects, r.path);
  EXPECT_FALSE(s.evaluate(sc.request.ego_pose, 0.0, 0, false).safe);
}

}  // namespace
}  // namespace pullout

namespace pullout {
namespace {

TEST(SafetyMonitor, HysteresisWidensTheMarginsOnceUnsafe) {
  StartPlannerParameters p;
  p.path_safety_check.safety_check_params.hysteresis_factor_expand_rate = 2.0;
  // A car 10 m behind on the road at y = -1: its box grown sideways by 2 m reaches
  // y = -1 + 0.95 + 2 = 1.95, short of the ego's right side on the shoulder (3.25 - 0.948 = 2.302);
  // grown by 4 m (factor 2) it reaches 3.95.
  const Object beside = car(2, 0.0, -1.0, 10.0);
  EXPECT_TRUE(monitor({beside}, straight_path(3.25), p).evaluate({10.0, 3.25, 0.0}, 0.0, 0, true).safe);
  auto m = monitor({car(1, -20.0, 0.0, 10.0)}, straight_path(3.25), p);
  ASSERT_FALSE(m.evaluate({10.0, 3.25, 0.0}, 0.0, 0, true).safe);
  m.update_objects({beside});
  EXPECT_FALSE(m.evaluate({10.0, 3.25, 0.0}, 0.0, 0, true).safe);  // previously unsafe: factor 2
}

}  // namespace
}  // namespace pullout
