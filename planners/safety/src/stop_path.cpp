#include "pullout/safety/stop_path.hpp"

#include <algorithm>
#include <cmath>

#include "pullout/geometry/polyline.hpp"
#include "pullout/safety/rss_check.hpp"

namespace pullout {

PullOutPath insert_feasible_stop(const PullOutPath& path, std::uint32_t segment_idx, const Pose2& ego, double velocity,
                                 const StopConditionParameters& p) {
  PullOutPath out = path;
  if (out.partial_paths.empty()) return out;
  const auto idx = std::min<std::size_t>(segment_idx, out.partial_paths.size() - 1);
  const double v0 = std::abs(velocity);
  const StopProfile stop(v0, p.maximum_deceleration_for_stop, p.maximum_jerk_for_stop);

  PathWithLaneId& segment = out.partial_paths[idx];
  std::vector<Vec2> points;
  points.reserve(segment.points.size());
  for (const PathPoint& q : segment.points) points.push_back(to_vec(q.pose));
  const Polyline line(points);
  const double s_ego = line.size() >= 2 ? line.project(to_vec(ego)).s : 0.0;
  for (PathPoint& q : segment.points) {
    const double s = line.size() >= 2 ? line.project(to_vec(q.pose)).s : 0.0;
    const double cap = stop.velocity_at(std::max(s - s_ego, 0.0));
    const double v = q.longitudinal_velocity_mps;
    q.longitudinal_velocity_mps = std::copysign(std::min(std::abs(v), cap), v);
    if (cap <= 0.0) q.longitudinal_velocity_mps = 0.0;
  }
  for (std::size_t i = idx + 1; i < out.partial_paths.size(); ++i) {
    for (PathPoint& q : out.partial_paths[i].points) q.longitudinal_velocity_mps = 0.0;
  }
  for (std::size_t i = idx; i < out.pairs_terminal_velocity_and_accel.size(); ++i) {
    out.pairs_terminal_velocity_and_accel[i] = {0.0, 0.0};
  }
  return out;
}

}  // namespace pullout
