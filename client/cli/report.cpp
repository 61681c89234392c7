#include "report.hpp"

#include <algorithm>
#include <cmath>

#include "pullout/geometry/polyline.hpp"

namespace pullout::cli {

namespace {

bool is_reverse(const PathWithLaneId& segment) {
  int positive = 0;
  int negative = 0;
  for (const auto& p : segment.points) {
    if (p.longitudinal_velocity_mps > 0.0) ++positive;
    if (p.longitudinal_velocity_mps < 0.0) ++negative;
  }
  if (positive != negative) return negative > positive;
  // A stopped segment (all velocities 0): tell the direction from the geometry.
  double along = 0.0;
  for (std::size_t i = 0; i + 1 < segment.points.size(); ++i) {
    const Pose2& a = segment.points[i].pose;
    const Pose2& b = segment.points[i + 1].pose;
    along += (b.x - a.x) * std::cos(a.yaw) + (b.y - a.y) * std::sin(a.yaw);
  }
  return along < 0.0;
}

void add_reason(std::vector<std::string>& reasons, const std::string& reason) {
  if (reason.empty()) return;
  if (std::find(reasons.begin(), reasons.end(), reason) == reasons.end()) reasons.push_back(reason);
}

}  // namespace

std::vector<SegmentSummary> summarize_segments(const PullOutPath& path) {
  std::vector<SegmentSummary> out;
  out.reserve(path.partial_paths.size());
  for (std::size_t i = 0; i < path.partial_paths.size(); ++i) {
    const PathWithLaneId& segment = path.partial_paths[i];
    SegmentSummary s;
    s.points = segment.points.size();
    s.reverse = is_reverse(segment);
    s.length_m = polyline_length(segment);
    if (i < path.pairs_terminal_velocity_and_accel.size()) {
      s.terminal_velocity_mps = path.pairs_terminal_velocity_and_accel[i].velocity_mps;
      s.terminal_accel_mps2 = path.pairs_terminal_velocity_and_accel[i].accel_mps2;
    }
    out.push_back(s);
  }
  return out;
}

PlanReport make_report(const PlanningResult& result) {
  PlanReport report;
  report.evaluation_table = result.evaluation_table;
  report.planning_time_ms = result.planning_time_ms;
  switch (result.outcome) {
    case PlanningResult::Outcome::kFound:
      report.found = true;
      report.state = ExecutionState::kWaitingApproval;
      report.stop_reason = "waiting approval";
      report.turn_signal = result.path.turn_signal;
      break;
    case PlanningResult::Outcome::kNoPath:
      report.state = ExecutionState::kNoPath;
      break;
    case PlanningResult::Outcome::kRejected:
      report.state = ExecutionState::kRejected;
      break;
  }
  if (result.outcome != PlanningResult::Outcome::kRejected) {
    report.path = result.path;
    report.planner = result.path.planner_type;
    report.segments = summarize_segments(result.path);
  }
  // A found path's reasons are notes on how it ends (where it stops before an object).
  for (const auto& reason : result.path.reasons) add_reason(report.reasons, reason);
  if (!report.found) {
    add_reason(report.reasons, result.stop_reason);
    if (result.timed_out) add_reason(report.reasons, "planning deadline expired");
  }
  for (const auto& issue : result.issues) {
    if (!report.error.empty()) report.error += '\n';
    report.error += issue.field + ": " + issue.problem;
  }
  return report;
}

PlanReport make_report(const std::optional<PullOutPath>& path, const PullOutStatus& status) {
  PlanReport report;
  report.state = status.state;
  report.evaluation_table = status.evaluation_table;
  report.planning_time_ms = status.planning_time_ms;
  report.error = status.error;
  report.planner = status.planner_type;
  report.stop_reason = status.stop_reason;
  report.turn_signal = status.turn_signal;
  report.safe = status.safe;
  // A rejected request has no path: the service's reply to one is empty (its poses 0) and repeats
  // the error as reasons, which `pullout request` never waits for; `pullout plan` gets it from the
  // session and printed both.
  if (path && status.state != ExecutionState::kRejected) {
    report.path = path;
    report.found = path->found && has_path(status.state);
    if (path->planner_type != PlannerType::kNone) report.planner = path->planner_type;
    report.segments = summarize_segments(*path);
    for (const auto& reason : path->reasons) add_reason(report.reasons, reason);
  }
  if (!report.found) add_reason(report.reasons, status.stop_reason);
  return report;
}

int exit_code(const PlanReport& report) {
  if (report.found) return 0;
  if (report.state == ExecutionState::kRejected) return 2;
  return 1;
}

}  // namespace pullout::cli
