#include "pullout/lane_planners/clothoid_pull_out.hpp"

#include <algorithm>
#include <cmath>

#include "pullout/geometry/angle.hpp"
#include "pullout/lane_planners/two_turn_path.hpp"
#include "turn_candidate.hpp"

namespace pullout {

PlannerCandidates ClothoidPullOut::plan(const PlanningContext& ctx, const Pose2& start,
                                        const StopCondition& stop) const {
  const auto& p = ctx.parameters;
  PlannerCandidates out;
  const Polyline window = turn_window(ctx, start);
  const double v0 = p.clothoid_initial_velocity;
  const double a = p.clothoid_acceleration;
  const double rate = p.clothoid_max_steer_angle_rate_deg_per_sec * kDegToRad;
  const double v_lane = speed_limit_at(ctx, ctx.road.centerline.project(to_vec(start)).s);
  for (double steer_deg : p.clothoid_max_steer_angles_deg) {
    out.stopped = stop.check();
    if (out.stopped != StopReason::kNone) break;
    const double steer = steer_deg * kDegToRad;
    PathCandidate candidate;
    if (steer > ctx.vehicle.max_steer_angle_rad) {
      candidate.rejection = Failure{AttemptOutcome::kNoGeometry,
                                    "steer angle " + format_fixed(steer_deg, 1) + " deg exceeds the vehicle's maximum"};
      out.candidates.push_back(std::move(candidate));
      continue;
    }
    const double kappa = std::tan(steer) / ctx.vehicle.wheel_base_m;
    const double clothoid_length = v0 * steer / rate;
    const auto turns = solve_two_turn(start, window, {kappa, kappa / clothoid_length, 0.0});
    if (!turns) {
      candidate.rejection = Failure{AttemptOutcome::kNoGeometry, "no clothoid path to the centerline"};
      out.candidates.push_back(std::move(candidate));
      continue;
    }
    const auto velocity = [v0, a, v_lane](double s) { return std::min(std::sqrt(v0 * v0 + 2.0 * a * s), v_lane); };
    const double v_end = velocity(turns->path.length());
    auto segment = [v_end, a](const std::vector<Pose2>&, const std::vector<std::size_t>&) {
      TurnSegmentation seg;
      seg.pairs = {{v_end, a}};
      return seg;
    };
    TurnCandidateOptions options;
    options.check_lanes = p.check_clothoid_path_lane_departure;
    options.departure_footprint = vehicle_footprint(ctx.vehicle, p.lane_departure_check_expansion_margin);
    options.collision_distance_from_end = p.clothoid_collision_check_distance_from_end;
    options.output_interval = p.center_line_path_interval;
    out.candidates.push_back(make_turn_candidate(ctx, *turns, options, velocity, segment));
  }
  return out;
}

}  // namespace pullout
