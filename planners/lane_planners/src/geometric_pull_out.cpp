#include "pullout/lane_planners/geometric_pull_out.hpp"

#include <algorithm>
#include <cmath>

#include "pullout/lane_planners/two_turn_path.hpp"
#include "turn_candidate.hpp"

namespace pullout {

namespace {
constexpr int kTangentLengths = 10;  // 0..9 m, as Autoware's end-pose offsets
}

PlannerCandidates GeometricPullOut::plan(const PlanningContext& ctx, const Pose2& start,
                                         const StopCondition& stop) const {
  const auto& p = ctx.parameters;
  PlannerCandidates out;
  const double steer = ctx.vehicle.max_steer_angle_rad * p.geometric_pull_out_max_steer_angle_margin_scale;
  const double kappa = std::tan(steer) / ctx.vehicle.wheel_base_m;
  const Polyline window = turn_window(ctx, start);
  const double v = p.geometric_pull_out_velocity;
  for (int k = 0; k < kTangentLengths; ++k) {
    out.stopped = stop.check();
    if (out.stopped != StopReason::kNone) break;
    const auto turns = solve_two_turn(start, window, {kappa, 0.0, static_cast<double>(k)});
    if (!turns) {
      PathCandidate none;
      none.rejection = Failure{AttemptOutcome::kNoGeometry, "no two-arc path to the centerline"};
      out.candidates.push_back(std::move(none));
      continue;
    }
    // The stop to re-steer is needed where the steering swaps sides (an S-shaped path); two turns
    // the same way (out of a perpendicular bay) flow into each other.
    const auto& pieces = turns->path.pieces();
    const bool s_shaped = turns->first_turn_pieces > 0 && turns->first_turn_pieces < pieces.size() &&
                          pieces.front().k0 * pieces.back().k0 < 0.0;
    const bool divide = p.divide_pull_out_path && s_shaped;
    const std::size_t first_turn = turns->first_turn_pieces;
    double first_turn_length = 0.0;
    for (std::size_t i = 0; i < first_turn; ++i) first_turn_length += pieces[i].length;
    // A short first arc cannot reach v comfortably before stopping: cruise at what
    // maximum_longitudinal_acc reaches over half of it.
    const double v1 = divide ? std::min(v, std::sqrt(p.maximum_longitudinal_acc * first_turn_length)) : v;
    auto segment = [divide, first_turn, v, v1](const std::vector<Pose2>& pts,
                                               const std::vector<std::size_t>& junctions) {
      TurnSegmentation seg;
      const auto length_between = [&pts](std::size_t a, std::size_t b) {
        double len = 0.0;
        for (std::size_t i = a + 1; i <= b; ++i) len += std::hypot(pts[i].x - pts[i - 1].x, pts[i].y - pts[i - 1].y);
        return len;
      };
      const std::size_t last = pts.size() - 1;
      if (divide && first_turn > 0 && first_turn <= junctions.size() && junctions[first_turn - 1] < last) {
        const std::size_t split = junctions[first_turn - 1];
        const double l1 = length_between(0, split);
        const double l2 = length_between(split, last);
        seg.splits = {split};
        seg.pairs = {{v1, v1 * v1 / l1}, {v, v * v / (2.0 * l2)}};
      } else {
        seg.pairs = {{v, v * v / (2.0 * length_between(0, last))}};
      }
      return seg;
    };
    TurnCandidateOptions options;
    options.check_lanes = true;
    options.departure_expansion = p.lane_departure_margin;
    options.collision_distance_from_end = p.geometric_collision_check_distance_from_end;
    options.output_interval = p.arc_path_interval;
    const auto velocity = [divide, first_turn_length, v, v1](double d) {
      return divide && d < 0.99 * first_turn_length ? v1 : v;  // chords are shorter than arcs
    };
    out.candidates.push_back(make_turn_candidate(ctx, *turns, options, velocity, segment));
  }
  return out;
}

}  // namespace pullout
