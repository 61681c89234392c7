#include "turn_candidate.hpp"

#include <algorithm>
#include <cmath>
#include <memory>

namespace pullout {

namespace {
// [m] pose spacing of the lane and collision checks on turns: at the tightest radius (about 5 m)
// a footprint corner moves along an arc whose sagitta between samples stays below 1 cm.
constexpr double kCheckInterval = 0.5;
constexpr double kWindowBehind = 5.0;  // [m] centerline window around the start
constexpr double kWindowAhead = 35.0;  // two turns and a 9 m tangent end within about 25 m
constexpr double kWindowStep = 1.0;

std::vector<double> cumulative_distance(const std::vector<Pose2>& poses) {
  std::vector<double> d(poses.size(), 0.0);
  for (std::size_t i = 1; i < poses.size(); ++i) {
    d[i] = d[i - 1] + std::hypot(poses[i].x - poses[i - 1].x, poses[i].y - poses[i - 1].y);
  }
  return d;
}
}  // namespace

Polyline turn_window(const PlanningContext& ctx, const Pose2& start) {
  const double s = ctx.road.centerline.project(to_vec(start)).s;
  return centerline_window(ctx, s - kWindowBehind, s + kWindowAhead, kWindowStep);
}

PathCandidate make_turn_candidate(
    const PlanningContext& ctx, const TwoTurnPath& turns, const TurnCandidateOptions& options, TurnVelocity velocity,
    std::function<TurnSegmentation(const std::vector<Pose2>&, const std::vector<std::size_t>&)> segment) {
  PathCandidate candidate;
  std::vector<Pose2> poses = turns.path.sample(kCheckInterval);
  const std::size_t turns_last = poses.size() - 1;
  const std::vector<double> dist = cumulative_distance(poses);
  const double section_end = dist.back() + options.collision_distance_from_end;
  std::size_t section_last = 0;
  while (section_last + 1 < poses.size() && dist[section_last + 1] <= section_end + 1e-9) ++section_last;
  if (options.collision_distance_from_end > 0.0) {
    // The section reaches past the end pose, along the road centerline.
    const double s_end = ctx.road.centerline.project(to_vec(poses.back())).s;
    for (double d = kCheckInterval; d <= options.collision_distance_from_end + 1e-9; d += kCheckInterval) {
      poses.push_back(ctx.road.centerline.pose_at(s_end + d));
    }
    section_last = poses.size() - 1;
  }
  check_candidate(ctx, poses, {options.check_lanes, options.departure_expansion, turns_last, section_last, turns_last},
                  candidate);

  auto shared_turns = std::make_shared<const TwoTurnPath>(turns);
  const double interval = options.output_interval;
  candidate.build = [&ctx, shared_turns, interval, velocity = std::move(velocity), segment = std::move(segment)]() {
    std::vector<std::size_t> junctions;
    const std::vector<Pose2> pts = shared_turns->path.sample(interval, junctions);
    const std::vector<double> d = cumulative_distance(pts);
    const TurnSegmentation seg = segment(pts, junctions);
    const Polyline& center = ctx.road.centerline;
    const double s_end = center.project(to_vec(pts.back())).s;
    const RoadEnd end = find_path_end(ctx, s_end);

    PullOutPath path;
    path.partial_paths.emplace_back();
    std::size_t next_split = 0;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      PathPoint p;
      p.pose = pts[i];
      p.longitudinal_velocity_mps = velocity(d[i]);
      p.lane_ids = lane_ids_at(ctx, to_vec(p.pose), road_lane_id_at(ctx, center.project(to_vec(p.pose)).s));
      if (next_split < seg.splits.size() && i == seg.splits[next_split]) {
        // The split point ends one partial path (stopped, to re-steer) and starts the next.
        PathPoint last = p;
        if (seg.stop_at_splits) last.longitudinal_velocity_mps = 0.0;
        path.partial_paths.back().points.push_back(std::move(last));
        path.partial_paths.emplace_back();
        ++next_split;
      }
      path.partial_paths.back().points.push_back(std::move(p));
    }
    std::vector<PathPoint> tail = centerline_points(ctx, s_end, end);
    auto& last_points = path.partial_paths.back().points;
    last_points.insert(last_points.end(), std::make_move_iterator(tail.begin()), std::make_move_iterator(tail.end()));
    if (end.is_goal && tail.empty()) last_points.back().longitudinal_velocity_mps = 0.0;
    path.pairs_terminal_velocity_and_accel = seg.pairs;
    path.start_pose = pts.front();
    path.end_pose = pts.back();
    path.shift_length_m = center.project(to_vec(pts.front())).lateral;
    return path;
  };
  return candidate;
}

}  // namespace pullout
