#include "text_output.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>

#include "pullout/geometry/angle.hpp"
#include "pullout/model/names.hpp"

namespace pullout::cli {

namespace {

// printf-style formatting into a std::string (the C locale: '.' as decimal point).
template <typename... Args>
std::string format(const char* fmt, Args... args) {
  const int n = std::snprintf(nullptr, 0, fmt, args...);
  if (n <= 0) return {};
  std::string s(static_cast<std::size_t>(n) + 1, '\0');
  std::snprintf(s.data(), s.size(), fmt, args...);
  s.resize(static_cast<std::size_t>(n));
  return s;
}

std::string optional_number(const std::optional<double>& v) { return v ? format("%.2f", *v) : std::string("-"); }

std::string pose_text(const Pose2& p) {
  return format("x %.3f m  y %.3f m  yaw %.1f deg", p.x, p.y, p.yaw * kRadToDeg);
}

void print_lines(std::ostream& out, const std::string& text, const char* prefix) {
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) out << prefix << line << '\n';
}

}  // namespace

void print_report(std::ostream& out, const PlanReport& report) {
  out << "found: " << (report.found ? "yes" : "no") << "   planner: " << to_string(report.planner)
      << "   state: " << to_string(report.state) << '\n';
  if (report.found) {
    out << "turn signal: " << to_string(report.turn_signal) << "   safe: " << (report.safe ? "yes" : "no") << '\n';
  }
  if (!report.stop_reason.empty() && report.state != ExecutionState::kNoPath) {
    out << "waiting: " << report.stop_reason << '\n';
  }

  if (report.state == ExecutionState::kRejected) {
    out << "request rejected:\n";
    print_lines(out, report.error.empty() ? std::string("(no detail given)") : report.error, "  ");
  }

  if (!report.segments.empty()) {
    out << (report.found ? "segments" : "stop path segments") << " (" << report.segments.size() << "):\n";
    out << format("  %3s  %-9s %7s %11s %13s %15s\n", "#", "direction", "points", "length [m]", "v_end [m/s]",
                  "a_end [m/s^2]");
    for (std::size_t i = 0; i < report.segments.size(); ++i) {
      const SegmentSummary& s = report.segments[i];
      out << format("  %3zu  %-9s %7zu %11.2f %13s %15s\n", i, s.reverse ? "reverse" : "forward", s.points, s.length_m,
                    optional_number(s.terminal_velocity_mps).c_str(), optional_number(s.terminal_accel_mps2).c_str());
    }
  }
  if (report.path) {
    out << "start pose: " << pose_text(report.path->start_pose) << '\n';
    out << "end pose:   " << pose_text(report.path->end_pose) << '\n';
  }
  if (report.found) {
    for (const auto& note : report.reasons) print_lines(out, note, "path end: ");
  }

  if (!report.evaluation_table.empty()) {
    const std::size_t n = report.evaluation_table.size();
    out << "evaluation table (" << n << (n == 1 ? " attempt" : " attempts") << "):\n";
    out << format("  %-10s %10s %13s  %s\n", "planner", "margin [m]", "backward [m]", "outcome");
    for (const auto& a : report.evaluation_table) {
      out << format("  %-10s %10.2f %13.2f  %s\n", to_string(a.planner), a.margin_m, a.backward_distance_m,
                    describe(a).c_str());
    }
  }
  out << format("planning time: %.2f ms\n", report.planning_time_ms);

  if (!report.found && !report.reasons.empty()) {
    out << "reasons:\n";
    for (const auto& reason : report.reasons) print_lines(out, reason, "  - ");
  }
}

}  // namespace pullout::cli
