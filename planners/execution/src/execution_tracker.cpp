#include "pullout/execution/execution_tracker.hpp"

#include <algorithm>
#include <cmath>

#include "pullout/geometry/polyline.hpp"

namespace pullout {

namespace {

// [m] lateral distance from the end pose within which driving past it counts as passing it.
constexpr double kPassLateralTolerance = 2.0;

// +1 when the segment is driven forward, -1 in reverse (sign of its first non-zero velocity).
double segment_direction(const PathWithLaneId& segment) {
  for (const PathPoint& p : segment.points) {
    if (p.longitudinal_velocity_mps > 0.0) return 1.0;
    if (p.longitudinal_velocity_mps < 0.0) return -1.0;
  }
  return 1.0;
}

}  // namespace

ExecutionTracker::ExecutionTracker(const ExecutionParameters& p)
    : th_arrived_distance_(p.th_arrived_distance),
      th_stopped_velocity_(p.th_stopped_velocity),
      th_stopped_time_(p.th_stopped_time) {}

void ExecutionTracker::start(const PullOutPath& path) {
  path_ = path;
  current_path_idx_ = 0;
  completed_ = false;
  stopped_since_.reset();
}

void ExecutionTracker::resume(const PullOutPath& path, std::uint32_t current_path_idx, bool completed) {
  start(path);
  const auto last = path.partial_paths.empty() ? 0u : static_cast<std::uint32_t>(path.partial_paths.size() - 1);
  current_path_idx_ = std::min(current_path_idx, last);
  completed_ = completed;
}

void ExecutionTracker::clear() {
  path_.reset();
  current_path_idx_ = 0;
  completed_ = false;
  stopped_since_.reset();
}

void ExecutionTracker::adopt(std::uint64_t request_id) {
  if (path_) path_->request_id = request_id;
}

ExecutionTracker::Update ExecutionTracker::on_progress(const ExecutionProgress& progress,
                                                       std::chrono::steady_clock::time_point received) {
  Update u{false, current_path_idx_, completed_};
  if (!path_ || progress.request_id != path_->request_id || completed_ || path_->partial_paths.empty()) return u;

  if (std::abs(progress.velocity_mps) < th_stopped_velocity_) {
    if (!stopped_since_) stopped_since_ = Since{progress.stamp_ns, received};
  } else {
    stopped_since_.reset();
  }
  bool stopped_long_enough = false;
  if (stopped_since_) {
    const double on_stamps = static_cast<double>(progress.stamp_ns - stopped_since_->stamp_ns) * 1e-9;
    const double on_clock = std::chrono::duration<double>(received - stopped_since_->received).count();
    stopped_long_enough = std::min(on_stamps, on_clock) >= th_stopped_time_;
  }

  const auto last = static_cast<std::uint32_t>(path_->partial_paths.size() - 1);
  const Vec2 p = to_vec(progress.pose);
  if (current_path_idx_ < last) {
    const PathWithLaneId& segment = path_->partial_paths[current_path_idx_];
    const Vec2 end = to_vec(segment.points.back().pose);
    if ((p - end).norm() < th_arrived_distance_ && stopped_long_enough) {
      ++current_path_idx_;
      stopped_since_.reset();
      u.changed = true;
    }
  } else {
    const double direction = segment_direction(path_->partial_paths[last]);
    const Vec2 local = to_local(path_->end_pose, p);
    if (local.x() * direction >= 0.0 && std::abs(local.y()) <= kPassLateralTolerance) {
      completed_ = true;
      u.changed = true;
    }
  }
  u.current_path_idx = current_path_idx_;
  u.completed = completed_;
  return u;
}

}  // namespace pullout
