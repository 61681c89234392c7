// Geometric pull-out: two circular arcs at the vehicle's tightest usable radius, joined by a common
// tangent of 0..9 m (the reverse of a parallel-parking manoeuvre; Vorobieva et al., IFAC 2013).
//
// Radius R = wheel_base / tan(max_steer_angle * geometric_pull_out_max_steer_angle_margin_scale).
// Candidates, tightest first: tangent lengths 0, 1, ..., 9 m (Autoware moves the end pose by the
// same offsets and recomputes one radius; a common tangent keeps both arcs at R and so the
// curvature within 1/R everywhere). Lane departure: the footprint, expanded by
// lane_departure_margin, must stay inside the lanes over the arcs, checked every 0.5 m.
//
// divide_pull_out_path = true: two partial paths, split at the end of the first arc where the
// vehicle stops to re-steer, when the arcs turn opposite ways (an S); false, or two arcs turning
// the same way (out of a perpendicular bay): one. Velocity on the arcs is geometric_pull_out_velocity v.
// Terminal pairs are physically consistent (constant acceleration a reaches v over a length L when
// a = v^2 / (2L)):
//   divided:  first  (v, v^2 / L1)     - reach v at half of the first arc, stop at its end;
//             second (v, v^2 / (2 L2)) - L2: from the re-start to the end pose;
//   single:           (v, v^2 / (2 L)).
// Autoware reads v from a field it never sets, so all its pairs are (0, 0), and its undivided
// formula parses as (v^2 / 2) * L.
#pragma once

#include "pullout/lane_planners/pull_out_planner.hpp"

namespace pullout {

class GeometricPullOut final : public PullOutPlanner {
 public:
  PlannerType type() const override { return PlannerType::kGeometric; }
  PlannerCandidates plan(const PlanningContext& context, const Pose2& start, const StopCondition& stop) const override;
};

}  // namespace pullout
