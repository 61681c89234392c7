// What the pullout CLI prints, independent of where the answer came from: an in-process plan
// (PlanningResult) or a reply of the service (PullOutPath + final PullOutStatus). Rendered as text
// (text_output.hpp), JSON (json_output.hpp) and SVG (svg_writer.hpp).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "pullout/model/types.hpp"
#include "pullout/pipeline/start_planner.hpp"

namespace pullout::cli {

// One partial path as the CLI reports it.
struct SegmentSummary {
  std::size_t points{0};
  bool reverse{false};  // driving direction (see summarize_segments)
  // From pairs_terminal_velocity_and_accel; absent when the path has fewer pairs than segments.
  std::optional<double> terminal_velocity_mps;
  std::optional<double> terminal_accel_mps2;
  double length_m{0.0};  // polyline length of the points [m]
};

struct PlanReport {
  bool found{false};
  PlannerType planner{PlannerType::kNone};
  // The service's state for this request; for an in-process plan, the state the service would
  // publish: waiting_approval (found), no_path or rejected.
  ExecutionState state{ExecutionState::kIdle};
  // Why the vehicle must stand (waiting_approval, waiting_safety, no_path), the turn signal of
  // the path and the dynamic safety at the service's last progress sample.
  std::string stop_reason;
  TurnSignal turn_signal{TurnSignal::kNone};
  bool safe{true};
  // The path (the stop path when nothing was found); absent for a rejected request or when the
  // service sent none.
  std::optional<PullOutPath> path;
  std::vector<SegmentSummary> segments;  // one per partial path of `path`
  std::vector<PlannerAttempt> evaluation_table;
  double planning_time_ms{0.0};
  std::vector<std::string> reasons;  // why no path was found; found: how the path ends
  std::string error;                 // rejected: "<field>: <problem>" lines
};

// Direction of a partial path: the sign of its non-zero point velocities (negative = reverse);
// when all are zero, the sign of the displacement projected on the heading.
std::vector<SegmentSummary> summarize_segments(const PullOutPath& path);

PlanReport make_report(const PlanningResult& result);
// `path` may be absent (rejected request, or the service sent no path).
PlanReport make_report(const std::optional<PullOutPath>& path, const PullOutStatus& status);

// The CLI's exit code for a report: 0 found, 1 no path, 2 rejected (bad input).
int exit_code(const PlanReport& report);

}  // namespace pullout::cli
