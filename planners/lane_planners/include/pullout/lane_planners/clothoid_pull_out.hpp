// Clothoid pull-out: two turns of clothoid - arc - clothoid, continuous in curvature.
//
// For each steer angle d in clothoid_max_steer_angles_deg (gentlest first): peak curvature
// k = tan(d) / wheel_base, clothoid length L_c = v0 * d / steer_rate (the distance covered while
// the wheel turns at clothoid_max_steer_angle_rate_deg_per_sec at clothoid_initial_velocity v0),
// i.e. sharpness k / L_c. Turns too small to reach k use two clothoids with a lower peak. Unlike
// Autoware, which rescales a clothoid polyline rigidly onto a two-arc solution (and so can exceed
// the curvature it was built for), the turns are solved directly, so |curvature| <= k <= 1/R_min
// everywhere. Angles above the vehicle's max steer are skipped.
//
// One partial path. Velocity on the turns v(s) = min(sqrt(v0^2 + 2 a s), lane speed limit) with
// a = clothoid_acceleration; pair (v at the end pose, a).
#pragma once

#include "pullout/lane_planners/pull_out_planner.hpp"

namespace pullout {

class ClothoidPullOut final : public PullOutPlanner {
 public:
  PlannerType type() const override { return PlannerType::kClothoid; }
  PlannerCandidates plan(const PlanningContext& context, const Pose2& start, const StopCondition& stop) const override;
};

}  // namespace pullout
