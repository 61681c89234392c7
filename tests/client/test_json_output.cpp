// The CLI's report (segment summaries, exit codes) and its JSON and text renderings, on
// hand-made paths and planning results.
#include <cmath>
#include <limits>
#include <sstream>

#include <gtest/gtest.h>

#include "json_output.hpp"
#include "pullout/geometry/angle.hpp"
#include "report.hpp"
#include "text_output.hpp"

namespace pullout::cli {
namespace {

// A straight segment of n points from (x0, y) along +x (yaw 0) spaced 1 m, at velocity v.
PathWithLaneId straight(double x0, double y, int n, double v, double step = 1.0) {
  PathWithLaneId segment;
  for (int i = 0; i < n; ++i) {
    PathPoint p;
    p.pose = {x0 + step * i, y, 0.0};
    p.longitudinal_velocity_mps = v;
    segment.points.push_back(p);
  }
  return segment;
}

// Reverse 3 m (points moving -x, heading +x, v < 0), then forward 10 m.
PullOutPath two_segment_path() {
  PullOutPath path;
  path.vehicle_id = "v1";
  path.request_id = 7;
  path.found = true;
  path.planner_type = PlannerType::kShift;
  path.partial_paths.push_back(straight(10.0, 3.5, 4, -1.0, -1.0));
  path.partial_paths.push_back(straight(7.0, 3.5, 11, 2.0));
  path.pairs_terminal_velocity_and_accel = {{0.0, -0.5}, {2.7, 0.0}};
  path.start_pose = {7.0, 3.5, 0.0};
  path.end_pose = {17.0, 3.5, kPi / 2};
  return path;
}

PlanningResult found_result() {
  PlanningResult result;
  result.outcome = PlanningResult::Outcome::kFound;
  result.path = two_segment_path();
  result.evaluation_table = {{PlannerType::kShift, 2.0, 0.0, AttemptOutcome::kCollision, "object 7 (4/4 candidates)"},
                             {PlannerType::kShift, 1.0, 3.0, AttemptOutcome::kSuccess, ""}};
  result.planning_time_ms = 4.25;
  return result;
}

TEST(SummarizeSegments, CountsLengthDirectionAndPairs) {
  const auto segments = summarize_segments(two_segment_path());
  ASSERT_EQ(segments.size(), 2u);
  EXPECT_EQ(segments[0].points, 4u);
  EXPECT_TRUE(segments[0].reverse);
  EXPECT_NEAR(segments[0].length_m, 3.0, 1e-12);  // 3 gaps of 1 m
  EXPECT_EQ(segments[1].points, 11u);
  EXPECT_FALSE(segments[1].reverse);
  EXPECT_NEAR(segments[1].length_m, 10.0, 1e-12);
  EXPECT_DOUBLE_EQ(*segments[1].terminal_velocity_mps, 2.7);
  EXPECT_DOUBLE_EQ(*segments[0].terminal_accel_mps2, -0.5);
}

TEST(SummarizeSegments, StoppedSegmentTakesDirectionFromGeometry) {
  PullOutPath path;
  path.partial_paths.push_back(straight(5.0, 0.0, 3, 0.0, -1.0));  // moves backwards, heading +x
  path.partial_paths.push_back(straight(0.0, 0.0, 3, 0.0, 1.0));
  const auto segments = summarize_segments(path);
  EXPECT_TRUE(segments[0].reverse);
  EXPECT_FALSE(segments[1].reverse);
  // More segments than pairs: the terminal values are unknown, not invented.
  EXPECT_FALSE(segments[0].terminal_velocity_mps.has_value());
}

TEST(JsonOutput, FoundPlanHasEveryField) {
  const PlanReport report = make_report(found_result());
  const nlohmann::ordered_json j = to_json(report);
  ASSERT_TRUE(j.is_object());
  for (const char* key : {"found", "planner", "state", "segments", "start_pose", "end_pose", "evaluation_table",
                          "planning_time_ms", "reasons", "error"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_EQ(j["found"], true);
  EXPECT_EQ(j["planner"], "shift");
  EXPECT_EQ(j["state"], "waiting_approval");
  EXPECT_EQ(j["stop_reason"], "waiting approval");
  EXPECT_EQ(j["safe"], true);
  ASSERT_EQ(j["segments"].size(), 2u);
  EXPECT_EQ(j["segments"][0]["points"], 4);
  EXPECT_EQ(j["segments"][0]["direction"], "reverse");
  EXPECT_EQ(j["segments"][1]["direction"], "forward");
  EXPECT_DOUBLE_EQ(j["segments"][1]["terminal_velocity"].get<double>(), 2.7);
  EXPECT_DOUBLE_EQ(j["segments"][0]["terminal_acceleration"].get<double>(), -0.5);
  EXPECT_NEAR(j["segments"][1]["length"].get<double>(), 10.0, 1e-12);
  EXPECT_DOUBLE_EQ(j["start_pose"]["x"].get<double>(), 7.0);
  EXPECT_DOUBLE_EQ(j["end_pose"]["yaw"].get<double>(), kPi / 2);
  ASSERT_EQ(j["evaluation_table"].size(), 2u);
  EXPECT_EQ(j["evaluation_table"][0]["planner"], "shift");
  EXPECT_DOUBLE_EQ(j["evaluation_table"][0]["margin"].get<double>(), 2.0);
  EXPECT_DOUBLE_EQ(j["evaluation_table"][1]["backward_distance"].get<double>(), 3.0);
  EXPECT_EQ(j["evaluation_table"][0]["outcome"], "collision");
  EXPECT_EQ(j["evaluation_table"][0]["detail"], "object 7 (4/4 candidates)");
  EXPECT_EQ(j["evaluation_table"][1]["outcome"], "success");
  EXPECT_EQ(j["evaluation_table"][1]["detail"], "");
  EXPECT_DOUBLE_EQ(j["planning_time_ms"].get<double>(), 4.25);
  EXPECT_TRUE(j["reasons"].is_array() && j["reasons"].empty());
  EXPECT_EQ(j["error"], "");
  EXPECT_EQ(exit_code(report), 0);
  // Keys in the documented order; a round trip through text gives the same object.
  EXPECT_EQ(j.dump().rfind("{\"found\":true,\"planner\":\"shift\",\"state\":\"waiting_approval\",\"stop_reason\":", 0),
            0u)
      << j.dump();
  EXPECT_EQ(nlohmann::ordered_json::parse(j.dump()), j);
}

TEST(JsonOutput, SegmentsCarryEveryPointOfThePath) {
  PullOutPath path = two_segment_path();
  path.partial_paths[1].points[4].pose.yaw = 0.25;  // a value that differs from its neighbours
  path.partial_paths[1].points[4].longitudinal_velocity_mps = 1.5;
  const nlohmann::ordered_json j = to_json(make_report(path, PullOutStatus{}));
  ASSERT_EQ(j["segments"].size(), path.partial_paths.size());
  for (std::size_t k = 0; k < path.partial_paths.size(); ++k) {
    const auto& points = path.partial_paths[k].points;
    const auto& json_points = j["segments"][k]["path"];
    ASSERT_TRUE(json_points.is_array()) << k;
    ASSERT_EQ(json_points.size(), points.size()) << k;
    EXPECT_EQ(j["segments"][k]["points"], points.size());  // the existing count stays
    for (std::size_t i = 0; i < points.size(); ++i) {
      EXPECT_DOUBLE_EQ(json_points[i]["x"].get<double>(), points[i].pose.x) << k << "/" << i;
      EXPECT_DOUBLE_EQ(json_points[i]["y"].get<double>(), points[i].pose.y) << k << "/" << i;
      EXPECT_DOUBLE_EQ(json_points[i]["yaw"].get<double>(), points[i].pose.yaw) << k << "/" << i;
      EXPECT_DOUBLE_EQ(json_points[i]["velocity"].get<double>(), points[i].longitudinal_velocity_mps) << k << "/" << i;
    }
  }
  EXPECT_DOUBLE_EQ(j["segments"][0]["path"][3]["x"].get<double>(), 7.0);  // reversing from 10 to 7
  EXPECT_DOUBLE_EQ(j["segments"][0]["path"][3]["velocity"].get<double>(), -1.0);
  EXPECT_DOUBLE_EQ(j["segments"][1]["path"][4]["yaw"].get<double>(), 0.25);
  // Survives a round trip through text.
  EXPECT_EQ(nlohmann::json::parse(j.dump())["segments"][1]["path"].size(), 11u);
}

TEST(JsonOutput, FoundPathNotesOnHowItEndsAreReasons) {
  PlanningResult result = found_result();
  result.path.reasons = {"stops 2.00 m before object 7, 21.3 m beyond the end pose"};
  const nlohmann::ordered_json j = to_json(make_report(result));
  ASSERT_EQ(j["reasons"].size(), 1u);
  EXPECT_EQ(j["reasons"][0], result.path.reasons[0]);
  std::ostringstream out;
  print_report(out, make_report(result));
  EXPECT_NE(out.str().find("path end: stops 2.00 m before object 7"), std::string::npos) << out.str();
}

TEST(JsonOutput, NoPathCarriesReasonsAndStopReasonOnce) {
  PlanningResult result;
  result.outcome = PlanningResult::Outcome::kNoPath;
  result.path.found = false;
  result.path.planner_type = PlannerType::kStop;
  result.path.reasons = {"shift: collision at margin 0.1 m", "no start candidate"};
  result.stop_reason = "no start candidate";  // already among the reasons: not repeated
  result.timed_out = true;
  const PlanReport report = make_report(result);
  const nlohmann::ordered_json j = to_json(report);
  EXPECT_EQ(j["found"], false);
  EXPECT_EQ(j["state"], "no_path");
  ASSERT_EQ(j["reasons"].size(), 3u);
  EXPECT_EQ(j["reasons"][1], "no start candidate");
  EXPECT_EQ(j["reasons"][2], "planning deadline expired");
  EXPECT_EQ(exit_code(report), 1);
}

TEST(JsonOutput, RejectedHasErrorLinesAndNoPoses) {
  PlanningResult result;
  result.outcome = PlanningResult::Outcome::kRejected;
  result.issues = {{"lanes[0].left_bound", "fewer than 2 points"}, {"goal_pose.yaw", "not finite"}};
  const PlanReport report = make_report(result);
  const nlohmann::ordered_json j = to_json(report);
  EXPECT_EQ(j["state"], "rejected");
  EXPECT_TRUE(j["start_pose"].is_null());
  EXPECT_TRUE(j["end_pose"].is_null());
  EXPECT_TRUE(j["segments"].empty());
  EXPECT_EQ(j["error"], "lanes[0].left_bound: fewer than 2 points\ngoal_pose.yaw: not finite");
  EXPECT_EQ(exit_code(report), 2);
}

TEST(JsonOutput, ServiceReplyUsesStatusTableAndState) {
  PullOutStatus status;
  status.request_id = 7;
  status.state = ExecutionState::kExecuting;
  status.planner_type = PlannerType::kShift;
  status.evaluation_table = {{PlannerType::kShift, 1.0, 0.0, AttemptOutcome::kLaneDeparture, "2/4 candidates"}};
  status.planning_time_ms = 1.5;
  const nlohmann::ordered_json j = to_json(make_report(two_segment_path(), status));
  EXPECT_EQ(j["found"], true);
  EXPECT_EQ(j["state"], "executing");
  EXPECT_EQ(j["segments"].size(), 2u);
  ASSERT_EQ(j["evaluation_table"].size(), 1u);
  EXPECT_EQ(j["evaluation_table"][0]["outcome"], "lane_departure");
  EXPECT_EQ(j["evaluation_table"][0]["detail"], "2/4 candidates");
  EXPECT_DOUBLE_EQ(j["planning_time_ms"].get<double>(), 1.5);

  PullOutStatus rejected;
  rejected.state = ExecutionState::kRejected;
  rejected.error = "ego_pose.orientation: not a unit quaternion";
  const PlanReport report = make_report(std::nullopt, rejected);
  EXPECT_EQ(to_json(report)["error"], rejected.error);
  EXPECT_EQ(exit_code(report), 2);
}

TEST(JsonOutput, NonFiniteNumbersBecomeNull) {
  PlanReport report = make_report(found_result());
  report.planning_time_ms = std::numeric_limits<double>::quiet_NaN();
  report.path->end_pose.x = std::numeric_limits<double>::infinity();
  const nlohmann::ordered_json j = to_json(report);
  EXPECT_TRUE(j["planning_time_ms"].is_null());
  EXPECT_TRUE(j["end_pose"]["x"].is_null());
  EXPECT_EQ(nlohmann::json::parse(j.dump())["end_pose"]["y"], 3.5);
}

TEST(TextOutput, FoundShowsSegmentsPosesTableAndTime) {
  std::ostringstream out;
  print_report(out, make_report(found_result()));
  const std::string text = out.str();
  EXPECT_NE(text.find("found: yes"), std::string::npos) << text;
  EXPECT_NE(text.find("planner: shift"), std::string::npos);
  EXPECT_NE(text.find("reverse"), std::string::npos);
  EXPECT_NE(text.find("forward"), std::string::npos);
  EXPECT_NE(text.find("start pose: x 7.000 m"), std::string::npos);
  EXPECT_NE(text.find("yaw 90.0 deg"), std::string::npos);
  EXPECT_NE(text.find("collision"), std::string::npos);
  EXPECT_NE(text.find("planning time: 4.25 ms"), std::string::npos);
  EXPECT_EQ(text.find("reasons:"), std::string::npos);
}

TEST(TextOutput, RejectedShowsEachErrorLine) {
  PlanningResult result;
  result.outcome = PlanningResult::Outcome::kRejected;
  result.issues = {{"lanes[0].left_bound", "fewer than 2 points"}, {"goal_pose.yaw", "not finite"}};
  std::ostringstream out;
  print_report(out, make_report(result));
  EXPECT_NE(out.str().find("request rejected:\n  lanes[0].left_bound: fewer than 2 points\n  goal_pose.yaw"),
            std::string::npos)
      << out.str();
}

}  // namespace
}  // namespace pullout::cli

namespace pullout::cli {
namespace {

TEST(JsonOutput, WaitingForSafetyIsAFoundPathWithTheReason) {
  PullOutStatus status;
  status.request_id = 8;
  status.state = ExecutionState::kWaitingSafety;
  status.stop_reason = "dynamic object risk: RSS distance to rear object 21 at t = 0.0 s";
  status.safe = false;
  status.unsafe_object_id = 21;
  status.turn_signal = TurnSignal::kRight;
  PullOutPath path = two_segment_path();
  path.found = true;
  const PlanReport report = make_report(path, status);
  const nlohmann::ordered_json j = to_json(report);
  EXPECT_EQ(j["found"], true);
  EXPECT_EQ(j["state"], "waiting_safety");
  EXPECT_EQ(j["stop_reason"], status.stop_reason);
  EXPECT_EQ(j["turn_signal"], "right");
  EXPECT_EQ(j["safe"], false);
  EXPECT_EQ(exit_code(report), 0);
}

}  // namespace
}  // namespace pullout::cli
