#include "json_output.hpp"

#include <cmath>

#include "pullout/model/names.hpp"

namespace pullout::cli {

namespace {

using Json = nlohmann::ordered_json;

Json number(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }

Json number(const std::optional<double>& v) { return v ? number(*v) : Json(nullptr); }

Json pose(const Pose2& p) { return Json{{"x", number(p.x)}, {"y", number(p.y)}, {"yaw", number(p.yaw)}}; }

// Every point of partial path k: pose and signed longitudinal velocity.
Json segment_points(const PlanReport& report, std::size_t k) {
  Json points = Json::array();
  if (!report.path || k >= report.path->partial_paths.size()) return points;
  for (const PathPoint& p : report.path->partial_paths[k].points) {
    points.push_back({{"x", number(p.pose.x)},
                      {"y", number(p.pose.y)},
                      {"yaw", number(p.pose.yaw)},
                      {"velocity", number(p.longitudinal_velocity_mps)}});
  }
  return points;
}

}  // namespace

nlohmann::ordered_json to_json(const PlanReport& report) {
  Json segments = Json::array();
  for (std::size_t k = 0; k < report.segments.size(); ++k) {
    const SegmentSummary& s = report.segments[k];
    segments.push_back({{"points", s.points},
                        {"direction", s.reverse ? "reverse" : "forward"},
                        {"terminal_velocity", number(s.terminal_velocity_mps)},
                        {"terminal_acceleration", number(s.terminal_accel_mps2)},
                        {"length", number(s.length_m)},
                        {"path", segment_points(report, k)}});
  }
  Json table = Json::array();
  for (const auto& a : report.evaluation_table) {
    table.push_back({{"planner", to_string(a.planner)},
                     {"margin", number(a.margin_m)},
                     {"backward_distance", number(a.backward_distance_m)},
                     {"outcome", to_string(a.outcome)},
                     {"detail", a.detail}});
  }
  Json out;
  out["found"] = report.found;
  out["planner"] = to_string(report.planner);
  out["state"] = to_string(report.state);
  out["stop_reason"] = report.stop_reason;
  out["turn_signal"] = to_string(report.turn_signal);
  out["safe"] = report.safe;
  out["segments"] = std::move(segments);
  out["start_pose"] = report.path ? pose(report.path->start_pose) : Json(nullptr);
  out["end_pose"] = report.path ? pose(report.path->end_pose) : Json(nullptr);
  out["evaluation_table"] = std::move(table);
  out["planning_time_ms"] = number(report.planning_time_ms);
  out["reasons"] = report.reasons;
  out["error"] = report.error;
  return out;
}

}  // namespace pullout::cli
