// Model <-> DDS message conversion: round trips, and the validation of inbound messages.
#include "pullout/idl/convert.hpp"

#include <cmath>
#include <iterator>
#include <limits>
#include <string>

#include <gtest/gtest.h>

namespace pullout::idl {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
// Yaw goes through sin/cos of yaw/2 and atan2: a few ulps of error, far below this.
constexpr double kYawTolerance = 1e-12;

PullOutRequest sample_request() {
  PullOutRequest r;
  r.vehicle_id = "car-7";
  r.request_id = 42;
  r.stamp_ns = 1'700'000'000'123'456'789;
  r.ego_pose = {10.0, 3.25, 0.1};
  r.ego_velocity_mps = 0.5;
  r.goal_pose = {90.0, 0.0, -0.2};
  Lane road;
  road.id = 1;
  road.subtype = LaneSubtype::kRoad;
  road.left_bound = {{0, 1.75}, {100, 1.75}};
  road.right_bound = {{0, -1.75}, {100, -1.75}};
  road.centerline = {{0, 0}, {100, 0}};
  road.speed_limit_mps = 13.9;
  Lane shoulder;
  shoulder.id = 2;
  shoulder.subtype = LaneSubtype::kRoadShoulder;
  shoulder.left_bound = {{0, 4.75}, {100, 4.75}};
  shoulder.right_bound = {{0, 1.75}, {100, 1.75}};
  r.lanes = {road, shoulder};
  r.route_lanelet_ids = {4618, 4635};
  Object car;
  car.id = 7;
  car.object_class = ObjectClass::kTruck;
  car.pose = {20.0, 3.5, 3.0};
  car.length_m = 6.0;
  car.width_m = 2.2;
  car.polygon = {{-3, -1.1}, {3, -1.1}, {3, 1.1}, {-3, 1.1}};
  car.velocity_mps = 0.2;
  car.predicted_paths = {PredictedPath{{{20, 3.5, 0}, {21, 3.5, 0.05}}, 0.5, 0.8}};
  r.objects = {car};
  OccupancyGrid grid;
  grid.resolution_m = 0.5;
  grid.origin = {-5, -5, 0.3};
  grid.width = 3;
  grid.height = 2;
  grid.data = {0, 100, -1, 50, 0, 0};
  r.occupancy_grid = grid;
  r.overrides.search_priority = {PlannerType::kShift, PlannerType::kGeometric};
  r.overrides.search_policy = SearchPolicy::kDistancePriority;
  r.deadline_ms = 150.0;
  return r;
}

void expect_pose_eq(const Pose2& a, const Pose2& b) {
  EXPECT_DOUBLE_EQ(a.x, b.x);
  EXPECT_DOUBLE_EQ(a.y, b.y);
  EXPECT_NEAR(a.yaw, b.yaw, kYawTolerance);
}

bool has_issue(const std::vector<RequestIssue>& issues, const std::string& field) {
  for (const auto& i : issues) {
    if (i.field == field) return true;
  }
  return false;
}

std::string dump(const std::vector<RequestIssue>& issues) {
  std::string s;
  for (const auto& i : issues) s += i.field + ": " + i.problem + "\n";
  return s;
}

TEST(Convert, RequestRoundTrip) {
  const PullOutRequest in = sample_request();
  std::vector<RequestIssue> issues;
  const PullOutRequest out = from_msg(to_msg(in), issues);
  EXPECT_TRUE(issues.empty()) << dump(issues);

  EXPECT_EQ(out.vehicle_id, in.vehicle_id);
  EXPECT_EQ(out.request_id, in.request_id);
  EXPECT_EQ(out.stamp_ns, in.stamp_ns);
  expect_pose_eq(out.ego_pose, in.ego_pose);
  EXPECT_DOUBLE_EQ(out.ego_velocity_mps, in.ego_velocity_mps);
  expect_pose_eq(out.goal_pose, in.goal_pose);
  ASSERT_EQ(out.lanes.size(), 2u);
  EXPECT_EQ(out.lanes[1].id, 2);
  EXPECT_EQ(out.lanes[1].subtype, LaneSubtype::kRoadShoulder);
  ASSERT_EQ(out.lanes[0].left_bound.size(), 2u);
  EXPECT_DOUBLE_EQ(out.lanes[0].left_bound[1].x, 100.0);
  EXPECT_DOUBLE_EQ(out.lanes[0].right_bound[0].y, -1.75);
  EXPECT_EQ(out.lanes[0].centerline.size(), 2u);
  EXPECT_TRUE(out.lanes[1].centerline.empty());
  EXPECT_DOUBLE_EQ(out.lanes[0].speed_limit_mps, 13.9);
  EXPECT_EQ(out.route_lanelet_ids, in.route_lanelet_ids);
  ASSERT_EQ(out.objects.size(), 1u);
  const Object& o = out.objects[0];
  EXPECT_EQ(o.id, 7);
  EXPECT_EQ(o.object_class, ObjectClass::kTruck);
  expect_pose_eq(o.pose, in.objects[0].pose);
  EXPECT_DOUBLE_EQ(o.length_m, 6.0);
  EXPECT_DOUBLE_EQ(o.width_m, 2.2);
  EXPECT_EQ(o.polygon.size(), 4u);
  EXPECT_DOUBLE_EQ(o.velocity_mps, 0.2);
  ASSERT_EQ(o.predicted_paths.size(), 1u);
  ASSERT_EQ(o.predicted_paths[0].poses.size(), 2u);
  expect_pose_eq(o.predicted_paths[0].poses[1], in.objects[0].predicted_paths[0].poses[1]);
  EXPECT_DOUBLE_EQ(o.predicted_paths[0].time_step_s, 0.5);
  EXPECT_DOUBLE_EQ(o.predicted_paths[0].confidence, 0.8);
  ASSERT_TRUE(out.occupancy_grid.has_value());
  EXPECT_DOUBLE_EQ(out.occupancy_grid->resolution_m, 0.5);
  expect_pose_eq(out.occupancy_grid->origin, in.occupancy_grid->origin);
  EXPECT_EQ(out.occupancy_grid->width, 3u);
  EXPECT_EQ(out.occupancy_grid->height, 2u);
  EXPECT_EQ(out.occupancy_grid->data, in.occupancy_grid->data);
  EXPECT_EQ(out.overrides.search_priority, in.overrides.search_priority);
  EXPECT_EQ(out.overrides.search_policy, in.overrides.search_policy);
  EXPECT_DOUBLE_EQ(out.deadline_ms, 150.0);
}

TEST(Convert, NoGridAndDefaultPolicyAreUnset) {
  PullOutRequest in = sample_request();
  in.occupancy_grid.reset();
  in.overrides.search_policy.reset();
  const msg::PullOutRequest m = to_msg(in);
  EXPECT_EQ(m.occupancy_grid().resolution_m(), 0.0);
  EXPECT_EQ(m.overrides().search_policy(), msg::POLICY_DEFAULT);
  std::vector<RequestIssue> issues;
  const PullOutRequest out = from_msg(m, issues);
  EXPECT_TRUE(issues.empty()) << dump(issues);
  EXPECT_FALSE(out.occupancy_grid.has_value());
  EXPECT_FALSE(out.overrides.search_policy.has_value());
}

TEST(Convert, YawOfMessageQuaternionIsNormalised) {
  // A quaternion a little off unit length (within the 1e-3 tolerance) gives the yaw of the
  // normalised one: 90 degrees about +z.
  msg::PullOutRequest m = to_msg(sample_request());
  const double s = 1.0005 * std::sqrt(0.5);
  m.ego_pose().orientation().z(s);
  m.ego_pose().orientation().w(s);
  std::vector<RequestIssue> issues;
  const PullOutRequest out = from_msg(m, issues);
  EXPECT_TRUE(issues.empty()) << dump(issues);
  EXPECT_NEAR(out.ego_pose.yaw, M_PI / 2.0, kYawTolerance);
}

TEST(Convert, YawFormulaWithRollAndPitch) {
  // Oracle: yaw = atan2(2(wz + xy), 1 - 2(y^2 + z^2)) for a unit quaternion with every component set.
  const double x = 0.1, y = 0.2, z = 0.3;
  const double w = std::sqrt(1.0 - x * x - y * y - z * z);
  msg::ExecutionProgress m;
  m.vehicle_id("v");
  m.pose().orientation().x(x);
  m.pose().orientation().y(y);
  m.pose().orientation().z(z);
  m.pose().orientation().w(w);
  std::vector<RequestIssue> issues;
  const ExecutionProgress p = from_msg(m, issues);
  EXPECT_TRUE(issues.empty()) << dump(issues);
  EXPECT_NEAR(p.pose.yaw, std::atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z)), kYawTolerance);
}

TEST(Convert, NonFiniteNumbersNameTheirField) {
  msg::PullOutRequest m = to_msg(sample_request());
  m.lanes()[1].left_bound()[1].x(kNaN);
  m.ego_pose().position().y(kInf);
  m.objects()[0].width_m(kNaN);
  m.objects()[0].predicted_paths()[0].path()[1].position().x(kNaN);
  m.occupancy_grid().resolution_m(kNaN);
  m.ego_velocity_mps(-kInf);
  m.deadline_ms(kNaN);
  std::vector<RequestIssue> issues;
  from_msg(m, issues);
  EXPECT_TRUE(has_issue(issues, "lanes[1].left_bound[1]")) << dump(issues);
  EXPECT_TRUE(has_issue(issues, "ego_pose.position")) << dump(issues);
  EXPECT_TRUE(has_issue(issues, "objects[0].width_m")) << dump(issues);
  EXPECT_TRUE(has_issue(issues, "objects[0].predicted_paths[0].path[1].position")) << dump(issues);
  EXPECT_TRUE(has_issue(issues, "occupancy_grid.resolution_m")) << dump(issues);
  EXPECT_TRUE(has_issue(issues, "ego_velocity_mps")) << dump(issues);
  EXPECT_TRUE(has_issue(issues, "deadline_ms")) << dump(issues);
  EXPECT_EQ(issues.size(), 7u) << dump(issues);
}

TEST(Convert, NonUnitQuaternionIsAnIssue) {
  msg::PullOutRequest m = to_msg(sample_request());
  m.ego_pose().orientation().w(2.0);
  m.goal_pose().orientation().z(kNaN);
  m.objects()[0].pose().orientation().w(0.0);
  m.objects()[0].pose().orientation().z(0.0);
  std::vector<RequestIssue> issues;
  from_msg(m, issues);
  EXPECT_TRUE(has_issue(issues, "ego_pose.orientation")) << dump(issues);
  EXPECT_TRUE(has_issue(issues, "goal_pose.orientation")) << dump(issues);
  EXPECT_TRUE(has_issue(issues, "objects[0].pose.orientation")) << dump(issues);
  EXPECT_EQ(issues.size(), 3u) << dump(issues);
}

TEST(Convert, QuaternionJustInsideToleranceIsAccepted) {
  msg::PullOutRequest m = to_msg(sample_request());
  m.ego_pose().orientation().x(0.0);
  m.ego_pose().orientation().y(0.0);
  m.ego_pose().orientation().z(0.0);
  m.ego_pose().orientation().w(1.0009);  // |norm - 1| = 9e-4 <= 1e-3
  std::vector<RequestIssue> issues;
  from_msg(m, issues);
  EXPECT_TRUE(issues.empty()) << dump(issues);
  m.ego_pose().orientation().w(1.0011);
  from_msg(m, issues);
  EXPECT_TRUE(has_issue(issues, "ego_pose.orientation")) << dump(issues);
}

TEST(Convert, UnknownEnumeratorsAreIssues) {
  msg::PullOutRequest m = to_msg(sample_request());
  m.lanes()[0].subtype(static_cast<msg::LaneSubtype>(9));
  m.objects()[0].classification(static_cast<msg::ObjectClass>(42));
  m.overrides().search_priority()[1] = 77;
  m.overrides().search_policy(static_cast<msg::SearchPolicy>(3));
  std::vector<RequestIssue> issues;
  from_msg(m, issues);
  EXPECT_TRUE(has_issue(issues, "lanes[0].subtype")) << dump(issues);
  EXPECT_TRUE(has_issue(issues, "objects[0].classification")) << dump(issues);
  EXPECT_TRUE(has_issue(issues, "overrides.search_priority[1]")) << dump(issues);
  EXPECT_TRUE(has_issue(issues, "overrides.search_policy")) << dump(issues);
}

// An Autoware route's segments cross the wire as LaneletSegment / LaneletPrimitive.
TEST(Convert, RouteSegmentsRoundTrip) {
  PullOutRequest in = sample_request();
  in.route_lanelet_ids.clear();
  in.route_segments = {{4618, {4618, 4619}}, {4635, {4635}}};
  std::vector<RequestIssue> issues;
  const msg::PullOutRequest m = to_msg(in);
  ASSERT_EQ(m.route_segments().size(), 2u);
  EXPECT_EQ(m.route_segments()[0].preferred_primitive().id(), 4618);
  EXPECT_EQ(m.route_segments()[0].primitives()[1].primitive_type(), "lane");
  const PullOutRequest out = from_msg(m, issues);
  EXPECT_TRUE(issues.empty()) << dump(issues);
  ASSERT_EQ(out.route_segments.size(), 2u);
  EXPECT_EQ(out.route_segments[0].preferred_id, 4618);
  EXPECT_EQ(out.route_segments[0].primitive_ids, (std::vector<std::int64_t>{4618, 4619}));
  EXPECT_EQ(out.route_segments[1].primitive_ids, (std::vector<std::int64_t>{4635}));
  EXPECT_TRUE(out.route_lanelet_ids.empty());
}

TEST(Convert, RoutePrimitiveThatIsNoLaneletIsAnIssue) {
  PullOutRequest in = sample_request();
  in.route_segments = {{4618, {4618, 4619}}};
  msg::PullOutRequest m = to_msg(in);
  m.route_segments()[0].primitives()[1].primitive_type("crosswalk");
  m.route_segments()[0].preferred_primitive().primitive_type("");  // empty: a lanelet
  std::vector<RequestIssue> issues;
  from_msg(m, issues);
  ASSERT_EQ(issues.size(), 1u) << dump(issues);
  EXPECT_TRUE(has_issue(issues, "route_segments[0].primitives[1].primitive_type")) << dump(issues);
}

TEST(Convert, GridSizeMismatchAndNegativeDeadline) {
  msg::PullOutRequest m = to_msg(sample_request());
  m.occupancy_grid().data().pop_back();
  m.deadline_ms(-5.0);
  std::vector<RequestIssue> issues;
  from_msg(m, issues);
  EXPECT_TRUE(has_issue(issues, "occupancy_grid.data")) << dump(issues);
  EXPECT_TRUE(has_issue(issues, "deadline_ms")) << dump(issues);
}

TEST(Convert, VehicleIdMustBeUsableAsKey) {
  msg::PullOutRequest m = to_msg(sample_request());
  m.vehicle_id("");
  std::vector<RequestIssue> issues;
  from_msg(m, issues);
  EXPECT_TRUE(has_issue(issues, "vehicle_id")) << dump(issues);
  issues.clear();
  m.vehicle_id(std::string(256, 'v'));
  from_msg(m, issues);
  EXPECT_TRUE(has_issue(issues, "vehicle_id")) << dump(issues);
}

TEST(Convert, IssueListIsCapped) {
  msg::PullOutRequest m = to_msg(sample_request());
  m.lanes()[0].left_bound().assign(1000, m.lanes()[0].left_bound()[0]);
  for (auto& p : m.lanes()[0].left_bound()) p.y(kNaN);
  std::vector<RequestIssue> issues;
  from_msg(m, issues);
  ASSERT_FALSE(issues.empty());
  EXPECT_LT(issues.size(), 100u);
  EXPECT_EQ(issues.front().field, "lanes[0].left_bound[0]");
  EXPECT_EQ(issues.back().field, "request");
  EXPECT_NE(issues.back().problem.find("more problems"), std::string::npos);
}

TEST(Convert, ProgressRoundTripAndValidation) {
  ExecutionProgress in;
  in.vehicle_id = "bus-1";
  in.request_id = 9;
  in.stamp_ns = -1'500'000'000;  // before the epoch: nanosec must still be in [0, 1e9)
  in.pose = {1.0, 2.0, -3.0};
  in.velocity_mps = -0.7;
  in.approved = false;
  const msg::ExecutionProgress m = to_msg(in);
  EXPECT_EQ(m.stamp().sec(), -2);
  EXPECT_EQ(m.stamp().nanosec(), 500'000'000u);
  std::vector<RequestIssue> issues;
  const ExecutionProgress out = from_msg(m, issues);
  EXPECT_TRUE(issues.empty()) << dump(issues);
  EXPECT_EQ(out.vehicle_id, "bus-1");
  EXPECT_EQ(out.request_id, 9u);
  EXPECT_EQ(out.stamp_ns, in.stamp_ns);
  expect_pose_eq(out.pose, in.pose);
  EXPECT_DOUBLE_EQ(out.velocity_mps, -0.7);
  EXPECT_FALSE(out.approved);

  msg::ExecutionProgress bad = m;
  bad.velocity_mps(kNaN);
  bad.pose().orientation().w(0.5);
  from_msg(bad, issues);
  EXPECT_TRUE(has_issue(issues, "velocity_mps")) << dump(issues);
  EXPECT_TRUE(has_issue(issues, "pose.orientation")) << dump(issues);
}

TEST(Convert, PathRoundTripWithShiftLength) {
  PullOutPath in;
  in.vehicle_id = "car-7";
  in.request_id = 42;
  in.stamp_ns = 123;
  in.found = true;
  in.planner_type = PlannerType::kShift;
  PathWithLaneId back;
  back.points = {PathPoint{{10, 3, 0}, -1.0, {2}}, PathPoint{{8, 3, 0}, 0.0, {2}}};
  PathWithLaneId forward;
  forward.points = {PathPoint{{8, 3, 0}, 0.0, {2}}, PathPoint{{30, 0, 0.01}, 2.0, {1, 2}}};
  in.partial_paths = {back, forward};
  in.pairs_terminal_velocity_and_accel = {{0.0, -0.5}, {2.0, 0.3}};
  in.start_pose = {10, 3, 0};
  in.end_pose = {30, 0, 0.01};
  in.shift_length_m = -3.25;
  in.turn_signal = TurnSignal::kRight;
  in.reasons = {"none"};

  const msg::PullOutPath m = to_msg(in);
  EXPECT_EQ(m.shift_length().start(), 0.0);
  EXPECT_EQ(m.shift_length().end(), -3.25);
  const PullOutPath out = from_msg(m);
  EXPECT_EQ(out.vehicle_id, in.vehicle_id);
  EXPECT_EQ(out.request_id, in.request_id);
  EXPECT_EQ(out.stamp_ns, in.stamp_ns);
  EXPECT_TRUE(out.found);
  EXPECT_EQ(out.planner_type, PlannerType::kShift);
  ASSERT_EQ(out.partial_paths.size(), 2u);
  ASSERT_EQ(out.partial_paths[1].points.size(), 2u);
  expect_pose_eq(out.partial_paths[1].points[1].pose, in.partial_paths[1].points[1].pose);
  EXPECT_DOUBLE_EQ(out.partial_paths[0].points[0].longitudinal_velocity_mps, -1.0);
  EXPECT_EQ(out.partial_paths[1].points[1].lane_ids, (std::vector<std::int64_t>{1, 2}));
  ASSERT_EQ(out.pairs_terminal_velocity_and_accel.size(), 2u);
  EXPECT_DOUBLE_EQ(out.pairs_terminal_velocity_and_accel[0].accel_mps2, -0.5);
  EXPECT_DOUBLE_EQ(out.pairs_terminal_velocity_and_accel[1].velocity_mps, 2.0);
  expect_pose_eq(out.start_pose, in.start_pose);
  expect_pose_eq(out.end_pose, in.end_pose);
  EXPECT_DOUBLE_EQ(out.shift_length_m, -3.25);
  EXPECT_EQ(out.turn_signal, TurnSignal::kRight);
  EXPECT_EQ(out.reasons, in.reasons);

  // A sender using a non-zero start: the model keeps the difference.
  msg::PullOutPath shifted = m;
  shifted.shift_length().start(1.0);
  shifted.shift_length().end(3.0);
  EXPECT_DOUBLE_EQ(from_msg(shifted).shift_length_m, 2.0);
}

TEST(Convert, StatusRoundTrip) {
  PullOutStatus in;
  in.vehicle_id = "car-7";
  in.request_id = 42;
  in.stamp_ns = 5;
  in.state = ExecutionState::kExecuting;
  in.current_path_idx = 1;
  in.segment_count = 2;
  in.planner_type = PlannerType::kShift;
  in.evaluation_table = {{PlannerType::kShift, 2.0, 0.0, AttemptOutcome::kCollision, "object 7 (4/4 candidates)"},
                         {PlannerType::kShift, 1.0, 0.0, AttemptOutcome::kSuccess, ""}};
  in.stop_reason = "";
  in.error = "a: b\nc: d";
  in.planning_time_ms = 12.5;
  const PullOutStatus out = from_msg(to_msg(in));
  EXPECT_EQ(out.vehicle_id, in.vehicle_id);
  EXPECT_EQ(out.request_id, in.request_id);
  EXPECT_EQ(out.stamp_ns, in.stamp_ns);
  EXPECT_EQ(out.state, ExecutionState::kExecuting);
  EXPECT_EQ(out.current_path_idx, 1u);
  EXPECT_EQ(out.segment_count, 2u);
  EXPECT_EQ(out.planner_type, PlannerType::kShift);
  ASSERT_EQ(out.evaluation_table.size(), 2u);
  EXPECT_DOUBLE_EQ(out.evaluation_table[0].margin_m, 2.0);
  EXPECT_EQ(out.evaluation_table[0].outcome, AttemptOutcome::kCollision);
  EXPECT_EQ(out.evaluation_table[0].detail, "object 7 (4/4 candidates)");
  EXPECT_EQ(out.evaluation_table[1].outcome, AttemptOutcome::kSuccess);
  EXPECT_EQ(out.error, in.error);
  EXPECT_DOUBLE_EQ(out.planning_time_ms, 12.5);

  // The departure and safety fields.
  in.state = ExecutionState::kWaitingSafety;
  in.stop_reason = "dynamic object risk: RSS distance to rear object 21 at t = 0.0 s";
  in.safe = false;
  in.unsafe_object_id = 21;
  in.departed = true;
  in.turn_signal = TurnSignal::kRight;
  in.turn_signal_start_ns = 1'700'000'000'123'456'789;
  in.path_end = "stops 2.01 m before object 7, 20.9 m beyond the end pose";
  const PullOutStatus waiting = from_msg(to_msg(in));
  EXPECT_EQ(waiting.path_end, in.path_end);
  EXPECT_EQ(waiting.state, ExecutionState::kWaitingSafety);
  EXPECT_EQ(waiting.stop_reason, in.stop_reason);
  EXPECT_FALSE(waiting.safe);
  EXPECT_EQ(waiting.unsafe_object_id, 21);
  EXPECT_TRUE(waiting.departed);
  EXPECT_EQ(waiting.turn_signal, TurnSignal::kRight);
  EXPECT_EQ(waiting.turn_signal_start_ns, in.turn_signal_start_ns);
  in.state = ExecutionState::kWaitingApproval;
  EXPECT_EQ(from_msg(to_msg(in)).state, ExecutionState::kWaitingApproval);
  in.state = ExecutionState::kExecuting;

  // Outbound types are not validated: an unknown state maps to the neutral value.
  msg::PullOutStatus m = to_msg(in);
  m.state(static_cast<msg::ExecutionState>(99));
  EXPECT_EQ(from_msg(m).state, ExecutionState::kIdle);
}

TEST(Convert, EveryAttemptOutcomeRoundTrips) {
  const AttemptOutcome all[] = {AttemptOutcome::kSuccess,       AttemptOutcome::kCollision,
                                AttemptOutcome::kLaneDeparture, AttemptOutcome::kNoGeometry,
                                AttemptOutcome::kStartInvalid,  AttemptOutcome::kGoalInvalid,
                                AttemptOutcome::kTimeout,       AttemptOutcome::kCancelled,
                                AttemptOutcome::kNodeLimit,     AttemptOutcome::kNoPath};
  PullOutStatus in;
  in.vehicle_id = "car-7";
  for (std::size_t i = 0; i < std::size(all); ++i) {
    in.evaluation_table.push_back({PlannerType::kGeometric, 0.5, 1.0, all[i], "detail " + std::to_string(i)});
  }
  const msg::PullOutStatus m = to_msg(in);
  // The wire value is the IDL's enumerator (the model's order), written out independently here.
  ASSERT_EQ(m.evaluation_table().size(), std::size(all));
  EXPECT_EQ(m.evaluation_table()[0].outcome(), msg::OUTCOME_SUCCESS);
  EXPECT_EQ(m.evaluation_table()[2].outcome(), msg::OUTCOME_LANE_DEPARTURE);
  EXPECT_EQ(m.evaluation_table()[7].outcome(), msg::OUTCOME_CANCELLED);
  EXPECT_EQ(m.evaluation_table()[9].outcome(), msg::OUTCOME_NO_PATH);
  std::vector<RequestIssue> issues;
  const PullOutStatus out = from_msg(m, issues);
  EXPECT_TRUE(issues.empty()) << dump(issues);
  ASSERT_EQ(out.evaluation_table.size(), std::size(all));
  for (std::size_t i = 0; i < std::size(all); ++i) {
    EXPECT_EQ(out.evaluation_table[i].outcome, all[i]) << i;
    EXPECT_EQ(out.evaluation_table[i].detail, "detail " + std::to_string(i));
    EXPECT_EQ(out.evaluation_table[i].planner, PlannerType::kGeometric);
  }
}

TEST(Convert, UnknownAttemptOutcomeIsReportedByField) {
  PullOutStatus in;
  in.evaluation_table = {{PlannerType::kShift, 1.0, 0.0, AttemptOutcome::kSuccess, ""},
                         {PlannerType::kShift, 0.5, 0.0, AttemptOutcome::kCollision, "object 3"}};
  msg::PullOutStatus m = to_msg(in);
  m.evaluation_table()[1].outcome(static_cast<msg::AttemptOutcome>(10));  // one past the last
  std::vector<RequestIssue> issues;
  const PullOutStatus out = from_msg(m, issues);
  ASSERT_EQ(issues.size(), 1u) << dump(issues);
  EXPECT_EQ(issues[0].field, "evaluation_table[1].outcome");
  EXPECT_NE(issues[0].problem.find("10"), std::string::npos) << issues[0].problem;
  // The row is kept, neutral, with the raw value for people.
  ASSERT_EQ(out.evaluation_table.size(), 2u);
  EXPECT_EQ(out.evaluation_table[0].outcome, AttemptOutcome::kSuccess);
  EXPECT_EQ(out.evaluation_table[1].outcome, AttemptOutcome::kNoPath);
  EXPECT_EQ(out.evaluation_table[1].detail, "unknown outcome 10: object 3");
  m.evaluation_table()[0].outcome(static_cast<msg::AttemptOutcome>(0xFFFFFFFFu));
  issues.clear();
  from_msg(m, issues);
  EXPECT_TRUE(has_issue(issues, "evaluation_table[0].outcome")) << dump(issues);
  EXPECT_TRUE(has_issue(issues, "evaluation_table[1].outcome")) << dump(issues);
}

TEST(Convert, TimeSaturatesOutsideInt32Seconds) {
  const msg::Time far = to_msg_time(std::numeric_limits<std::int64_t>::max());
  EXPECT_EQ(far.sec(), std::numeric_limits<std::int32_t>::max());
  const msg::Time t = to_msg_time(1'000'000'001);
  EXPECT_EQ(t.sec(), 1);
  EXPECT_EQ(t.nanosec(), 1u);
  EXPECT_EQ(from_msg_time(t), 1'000'000'001);
}

}  // namespace
}  // namespace pullout::idl

namespace pullout::idl {
namespace {

TEST(Convert, TheRequestsVehicleRoundTrips) {
  PullOutRequest in = sample_request();
  std::vector<RequestIssue> issues;
  EXPECT_FALSE(from_msg(to_msg(in), issues).vehicle);  // none given: none on the wire
  in.vehicle_profile = "bus";
  EXPECT_EQ(from_msg(to_msg(in), issues).vehicle_profile, "bus");
  in.vehicle_profile.clear();
  VehicleInfo v;
  v.wheel_base_m = 5.9;
  v.rear_overhang_m = 3.5;
  v.max_steer_angle_rad = 0.6;
  in.vehicle = v;
  const PullOutRequest out = from_msg(to_msg(in), issues);
  ASSERT_TRUE(out.vehicle);
  EXPECT_EQ(*out.vehicle, v);
  EXPECT_TRUE(issues.empty());
}

TEST(Convert, MoreThanOneVehicleIsAnIssue) {
  msg::PullOutRequest m = to_msg(sample_request());
  m.vehicle().resize(2);
  std::vector<RequestIssue> issues;
  from_msg(m, issues);
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_EQ(issues[0].field, "vehicle");
}

TEST(Convert, TheVehicleWaitedForRoundTrips) {
  PullOutStatus s;
  s.vehicle_id = "fleet-b";
  s.waiting_for_vehicle_id = "fleet-a";
  EXPECT_EQ(from_msg(to_msg(s)).waiting_for_vehicle_id, "fleet-a");
}

}  // namespace
}  // namespace pullout::idl
