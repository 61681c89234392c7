#include "live_view_support.hpp"

#include <chrono>
#include <sstream>

namespace pullout::integration {

using namespace std::chrono_literals;

void SegmentDriver::report(const Pose2& pose, double velocity_mps) {
  client_.report_progress(progress_sample(id_, stamp_ns_, pose, velocity_mps, true));
}

std::optional<PullOutStatus> SegmentDriver::depart() {
  const Pose2 start = path_.partial_paths.front().points.front().pose;
  std::optional<PullOutStatus> st;
  // The progress topic keeps the last sample per vehicle: one sample every 50 ms (0.1 s later on
  // the vehicle's clock), at most 200 of them.
  for (int j = 0; j < 200 && !st; ++j) {
    stamp_ns_ += 100'000'000;
    report(start, 0.0);
    st = client_.wait_for_status(
        id_, [](const PullOutStatus& s) { return s.state == ExecutionState::kExecuting; }, 50ms);
  }
  return st;
}

std::optional<PullOutStatus> SegmentDriver::drive_segment() {
  if (segment_ + 1 >= path_.partial_paths.size()) return std::nullopt;
  const auto& points = path_.partial_paths[segment_].points;
  for (std::size_t i = 0; i < points.size(); ++i) {
    // 20 ms per point: samples sent in a burst must not run ahead of the service's clock by more
    // than the session's stamp tolerance.
    stamp_ns_ += 20'000'000;
    const bool last_point = i + 1 == points.size();
    const double v = points[i].longitudinal_velocity_mps;
    report(points[i].pose, last_point ? 0.0 : (v == 0.0 ? 0.5 : v));
  }
  // Stand still at the segment end (th_stopped_time is 1 s on the stamps): one sample every
  // 50 ms, each 0.5 s later on the vehicle's clock, until the service moves on.
  const std::uint32_t next = static_cast<std::uint32_t>(segment_ + 1);
  std::optional<PullOutStatus> st;
  for (int j = 0; j < 40 && !st; ++j) {
    stamp_ns_ += 500'000'000;
    report(points.back().pose, 0.0);
    st = client_.wait_for_status(
        id_, [next](const PullOutStatus& s) { return s.current_path_idx == next; }, 50ms);
  }
  if (st) segment_ = next;
  return st;
}

void SegmentDriver::keep_alive() {
  const auto& points = path_.partial_paths[segment_].points;
  stamp_ns_ += 100'000'000;
  report(points.front().pose, points.front().longitudinal_velocity_mps < 0.0 ? -0.2 : 0.2);
}

KeepAlive::KeepAlive(SegmentDriver& driver)
    : thread_([this, &driver] {
        while (!stop_.load()) {
          driver.keep_alive();
          std::this_thread::sleep_for(100ms);
        }
      }) {}

KeepAlive::~KeepAlive() {
  stop_.store(true);
  thread_.join();
}

std::vector<std::vector<std::string>> last_table_rows(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream lines(text);
  std::string line;
  bool header_seen = false;
  while (std::getline(lines, line)) {
    if (line.rfind("pullout watch", 0) == 0) {  // a new table starts
      rows.clear();
      header_seen = false;
      continue;
    }
    if (line.rfind("VEHICLE", 0) == 0) {
      header_seen = true;
      continue;
    }
    if (!header_seen || line.empty() || line == "(no vehicles)") continue;
    std::istringstream cells(line);
    std::vector<std::string> row;
    std::string cell;
    while (cells >> cell) row.push_back(cell);
    rows.push_back(std::move(row));
  }
  return rows;
}

}  // namespace pullout::integration
