// Follows a vehicle through the segments (partial paths) of its PullOutPath.
//
// A segment that is not the last is finished when the vehicle is within th_arrived_distance of the
// segment's last point and has been stopped (|v| < th_stopped_velocity) for th_stopped_time,
// measured on the progress stamps (the vehicle's clock) and never credited more than the time the
// caller's clock saw pass between those samples (a sample stamped far ahead cannot stand in for a
// standstill that did not happen). current_path_idx then increments, clamped
// to the last segment. The last segment is finished when the vehicle passes the path's end_pose
// (in the driving direction of that segment), which completes the execution.
//
// Not thread-safe: one tracker per vehicle, used under the caller's lock.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>

#include "pullout/execution/execution_parameters.hpp"
#include "pullout/model/types.hpp"

namespace pullout {

class ExecutionTracker {
 public:
  explicit ExecutionTracker(const ExecutionParameters& parameters);

  // Starts following `path` (a found path) from segment 0.
  void start(const PullOutPath& path);
  // Follows `path` from segment `current_path_idx` (clamped to the last), completed or not: a
  // session restored from a snapshot. The standstill is measured afresh.
  void resume(const PullOutPath& path, std::uint32_t current_path_idx, bool completed);
  // Forgets the path (no path, rejected request).
  void clear();
  // Keeps following the same path, with its segment index and stop timer, under another request
  // id (a re-sent request of the vehicle while the path is latched).
  void adopt(std::uint64_t request_id);

  // Forgets when the vehicle stopped (its clock changed): the standstill is measured afresh.
  void restart_standstill() { stopped_since_.reset(); }

  struct Update {
    bool changed{false};  // current_path_idx or completion changed with this sample
    std::uint32_t current_path_idx{0};
    bool completed{false};
  };
  // Feeds one odometry sample, received at `received` on the caller's steady clock. Samples for
  // another request id are ignored (changed = false). The caller filters implausible stamps.
  Update on_progress(const ExecutionProgress& progress, std::chrono::steady_clock::time_point received);

  bool active() const { return path_.has_value(); }
  std::uint32_t current_path_idx() const { return current_path_idx_; }
  bool completed() const { return completed_; }
  std::uint64_t request_id() const { return path_ ? path_->request_id : 0; }

 private:
  double th_arrived_distance_;
  double th_stopped_velocity_;
  double th_stopped_time_;
  std::optional<PullOutPath> path_;
  std::uint32_t current_path_idx_{0};
  bool completed_{false};
  // When the vehicle has been stopped since: the sample's stamp and when it was received.
  struct Since {
    std::int64_t stamp_ns{0};
    std::chrono::steady_clock::time_point received{};
  };
  std::optional<Since> stopped_since_;
};

}  // namespace pullout
