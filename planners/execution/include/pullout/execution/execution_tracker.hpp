// Follows a vehicle through the segments (partial paths) of its PullOutPath.
//
// A segment that is not the last is finished when the vehicle is within th_arrived_distance of the
// segment's last point and has been stopped (|v| < th_stopped_velocity) for th_stopped_time,
// measured on the progress stamps (the vehicle's clock). current_path_idx then increments, clamped
// to the last segment. The last segment is finished when the vehicle passes the path's end_pose
// (in the driving direction of that segment), which completes the execution.
//
// Not thread-safe: one tracker per vehicle, used under the caller's lock.
#pragma once

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
  // Forgets the path (no path, rejected request).
  void clear();
  // Keeps following the same path, with its segment index and stop timer, under another request
  // id (a re-sent request of the vehicle while the path is latched).
  void adopt(std::uint64_t request_id);

  struct Update {
    bool changed{false};  // current_path_idx or completion changed with this sample
    std::uint32_t current_path_idx{0};
    bool completed{false};
  };
  // Feeds one odometry sample. Samples for another request id are ignored (changed = false).
  Update on_progress(const ExecutionProgress& progress);

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
  std::optional<std::int64_t> stopped_since_ns_;  // stamp from which the vehicle has been stopped
};

}  // namespace pullout
