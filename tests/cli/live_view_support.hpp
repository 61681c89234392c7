// Shared by the live-view tests (pullout watch, pullout view): a simulated vehicle that drives the
// real service's path segment by segment over DDS, so that what the view shows can be checked
// against the statuses the vehicle itself received.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <thread>

#include "integration_support.hpp"

namespace pullout::integration {

class SegmentDriver {
 public:
  SegmentDriver(Client& client, std::uint64_t request_id, PullOutPath path)
      : client_(client), id_(request_id), path_(std::move(path)) {}

  // Approves and drives along the current segment (one progress sample per path point, 20 ms
  // apart on the vehicle's clock), then stands still at its end until the service moves
  // current_path_idx to the next segment. Returns the status that says so (nullopt: the service
  // did not advance within the bound). Only for a segment that is not the last.
  std::optional<PullOutStatus> drive_segment();

  // Sends approved, standing samples at the start pose until the service says executing (the
  // vehicle is released on segment 0). Returns that status.
  std::optional<PullOutStatus> depart();

  // One sample that keeps the service from stopping the vehicle for lost odometry
  // (progress_timeout_s) while a test looks at the view: at the start of the current segment,
  // 100 ms later on the vehicle's clock, moving slowly in the segment's direction (so the segment
  // is not taken as finished).
  void keep_alive();

  std::size_t segment() const { return segment_; }

 private:
  void report(const Pose2& pose, double velocity_mps);

  Client& client_;
  std::uint64_t id_;
  PullOutPath path_;
  std::size_t segment_{0};
  std::int64_t stamp_ns_{1'000'000'000};
};

// Calls driver.keep_alive() every 100 ms on a thread of its own while it exists. The driver must
// not be used by another thread meanwhile.
class KeepAlive {
 public:
  explicit KeepAlive(SegmentDriver& driver);
  ~KeepAlive();
  KeepAlive(const KeepAlive&) = delete;
  KeepAlive& operator=(const KeepAlive&) = delete;

 private:
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

// The rows of a `pullout watch` table (the last one in `text`, whose tables are separated by blank
// lines), each split at runs of spaces; the header row is left out. The NOTE column may hold
// several words: use only the first six cells (vehicle, state, planner, segment, safe, age).
std::vector<std::vector<std::string>> last_table_rows(const std::string& text);

}  // namespace pullout::integration
