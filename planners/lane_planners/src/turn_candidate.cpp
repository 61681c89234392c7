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

constexpr int kGoldenIterations = 10;  // a bracket of 2 kCheckInterval shrinks to about 8 mm

// Pose at distance s along the path (clamped).
Pose2 pose_along(const CurvaturePath& path, double s) {
  Pose2 p = path.start();
  for (const CurvaturePiece& piece : path.pieces()) {
    if (s <= piece.length) return CurvaturePath::advance(p, piece, std::max(s, 0.0));
    s -= piece.length;
    p = CurvaturePath::advance(p, piece, piece.length);
  }
  return p;
}

std::vector<double> cumulative_distance(const std::vector<Pose2>& poses) {
  std::vector<double> d(poses.size(), 0.0);
  for (std::size_t i = 1; i < poses.size(); ++i) {
    d[i] = d[i - 1] + std::hypot(poses[i].x - poses[i - 1].x, poses[i].y - poses[i - 1].y);
  }
  return d;
}
}  // namespace

// The smallest clearance to the obstacles over the path's first `length` metres. Samples every
// kCheckInterval can miss the closest approach of a corner passing an obstacle's corner by
// centimetres. The clearance is Lipschitz in the distance driven, with constant
// L = 1 + max|curvature| * (the footprint's bounding radius) (the fastest point of the
// footprint), so the true minimum lies within one interval of a sample whose clearance is less
// than L * interval / 2 above the smallest sampled one, and that is a local minimum of the
// samples; around each such sample the closest approach (one per obstacle passed: the distance is
// unimodal there) is found by golden-section search. Skipped when even the lowest possible value
// stays above the context's clearance_horizon.
ObjectChecker::Clearance refined_clearance(const PlanningContext& ctx, const CurvaturePath& path, double length) {
  const double lipschitz = 1.0 + path.max_abs_curvature() * ctx.objects.footprint().bounding_radius();
  const int n = std::max(1, static_cast<int>(std::ceil(length / kCheckInterval)));
  const double step = length / n;
  const double slack = 0.5 * lipschitz * step;
  ObjectChecker::Clearance best;
  // Clearances above the best so far plus the slack cannot matter (neither as a minimum nor to
  // tell one): they come back as +inf, cheaply, from bounding circles.
  const auto at = [&](double s) {
    const double h = std::min(ctx.clearance_horizon, best.distance + slack);
    const auto c = ctx.objects.clearance(pose_along(path, s), h);
    if (c.distance < best.distance) best = c;
    return c.distance;
  };
  std::vector<double> sampled(static_cast<std::size_t>(n) + 1);
  for (int i = 0; i <= n; ++i) {
    sampled[i] = at(step * i);
    if (best.distance <= 0.0) return best;
  }
  const double sampled_best = best.distance;
  // Nothing within reach of the largest margin: the exact value does not matter.
  if (!(sampled_best - slack < ctx.clearance_horizon)) return best;
  constexpr double kGolden = 0.6180339887498949;
  for (int i = 0; i <= n; ++i) {
    // A closest approach between samples makes one of its two neighbours a local minimum of the
    // samples; the bracket covers both intervals beside it.
    const bool local_min = (i == 0 || sampled[i] <= sampled[i - 1]) && (i == n || sampled[i] <= sampled[i + 1]);
    if (!local_min || !(sampled[i] < sampled_best + slack)) continue;
    double a = std::max(0.0, step * (i - 1));
    double b = std::min(length, step * (i + 1));
    double x1 = b - kGolden * (b - a);
    double x2 = a + kGolden * (b - a);
    double f1 = at(x1);
    double f2 = at(x2);
    for (int k = 0; k < kGoldenIterations && best.distance > 0.0; ++k) {
      if (f1 < f2) {
        b = x2;
        x2 = x1;
        f2 = f1;
        x1 = b - kGolden * (b - a);
        f1 = at(x1);
      } else {
        a = x1;
        x1 = x2;
        f1 = f2;
        x2 = a + kGolden * (b - a);
        f2 = at(x2);
      }
    }
  }
  return best;
}

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
  check_candidate(ctx, poses, {options.check_lanes, options.departure_footprint, turns_last, section_last, turns_last},
                  candidate);
  if (!candidate.rejection) {
    // The sampled clearance over the turns, made exact (see refined_clearance). A rejected
    // candidate stays rejected whatever its exact clearance.
    const double turns_section = std::min(section_end, dist.back());
    const auto refined = refined_clearance(ctx, turns.path, turns_section);
    if (refined.distance < candidate.clearance) {
      candidate.clearance = refined.distance;
      candidate.nearest_obstacle = refined.obstacle_id;
    }
    if (candidate.clearance < 1e-6) {  // contact, as check_candidate counts it
      candidate.rejection = Failure{AttemptOutcome::kCollision, "object " + std::to_string(candidate.nearest_obstacle)};
    }
  }

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
