// Geometric pull-out: two circular arcs turning opposite ways (an S), the reverse of a
// parallel-parking manoeuvre (Vorobieva et al., IFAC 2013), as Autoware's.
//
// R_min = wheel_base / tan(max_steer_angle * geometric_pull_out_max_steer_angle_margin_scale).
// The first arc (out of the spot) has radius R1 = R_min; the end pose lies on the road
// centerline, 2 sqrt(R1^2 - (R1 - d/2)^2) ahead of the start (d: the start's lateral offset from
// the centerline; where two arcs of R1 would end) plus an offset of 0, 1, ..., 9 m (the
// candidates, tightest first), and the second arc's radius is solved so that the S ends exactly
// there (solve_arc_pair; the first arc turns towards the side of the start's heading line the end
// lies on, or, where that gives no S, towards the road as Autoware's always does: a start turned
// towards the road with the road bending back has the end on its kerb side): R2 = R1 at offset 0
// and grows with it. A larger R2 swings the front
// corner on the road side less far beyond the end pose (by hypot(R2 + w, front) - (R2 + w)),
// which is what lets the vehicle pull out onto a single road lane with no opposite lane to swing
// into.
//
// Before the footprint check, the swing of the outermost corners is checked analytically (exact
// on a straight road): the front corner on the road side over the second arc against the lane
// edge beyond the end pose, and the rear corner on the kerb side over the first arc against the
// kerb-side lane edge; a candidate that fails is rejected as lane departure. Unlike Autoware, when
// the rear corner's swing at R_min would cross the kerb-side edge (a car parked close to the
// kerb), R1 is raised to the smallest radius whose swing fits with 1 cm to spare, rather than
// giving up. Where no S reaches the end pose (a start across the road: out of a perpendicular
// bay), the candidate is two turns at R_min joined by a common tangent of the offset's length (the
// same way or opposite ways, solve_two_turn).
//
// Lane departure: a footprint expanded per side must stay inside the lanes (in the analytic check
// and in the footprint check over the arcs, every 0.5 m). The road side (towards the end pose) is
// expanded by lane_departure_margin m, always. The front and the rear by m, or by the start pose's
// own clearance there when that is smaller: a start is never required to be further inside the
// lanes than it already is. The kerb side by
//   m_kerb = clamp(g - s - 1 cm, min(lane_departure_check_expansion_margin, m), m),
// g the start's clearance on the kerb side (measured with the front and rear expansions, so the
// corners count), s the swing of the expanded rear corner on a first arc at R_min: the margin
// stays whole where the room beside the car allows it, and yields, down to Autoware's footprint
// check (expansion 0 by default), to what the tightest first turn needs in a car parked closer
// (0.15-0.3 m from the kerb is how cars are parked). Below that the first arc widens (above).
// Autoware checks the footprint unexpanded and the kerb-side swing with the whole margin, so its
// geometric pull-out fails from a car parked within about 0.3 m of the kerb.
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
//
// Shunting (geometric_pull_out_max_shunts > 0; the multi-step un-parking of Vorobieva et al.):
// where no single S gets out of a parallel spot (less than about 2.2 m of room ahead and behind
// together), the pipeline asks plan_multi_move() from the vehicle's pose, after the margin ladder
// found nothing. The manoeuvre, as a driver does it:
//   0. reverse straight until just clear of what is behind (enable_back; up to
//      max_back_distance);
//   1. from the pose reached, try the S above (with a tilted start: the kerb-side swing and gap
//      are taken across the tilted lane edge); if one is usable at the smallest margin, done;
//   2. else drive forward at full lock towards the road (radius R_min) until just clear of what is
//      ahead (or after turning by 22.5 degrees), then reverse at full lock the other way until
//      just clear of what is behind (where the rear corner meets the kerb at once: straight back):
//      both turn the vehicle further towards the road; back to 1, at most
//      geometric_pull_out_max_shunts times. From a turned pose, two turns joined by a 0..9 m
//      tangent are tried after the S (a counter-arc onto the lane), at R_min, then at 2 and 3.3
//      R_min: straightening from a pose turned across a single road lane at R_min swings the
//      front corner on the road side over the far edge.
//   Where that gets stuck with the rear corner on the kerb side at the kerb ("no room to reverse":
//   each reverse arc takes it towards the kerb, and once the vehicle is turned about 10 degrees
//   every reverse does; a car parked 0.15 m from the kerb), the manoeuvre is planned again with
//   creeping after 0.: forward at full lock towards the road over half the room ahead, at full
//   lock the other way back to the start's heading, straight back until just clear; the vehicle
//   ends 2 R_min (1 - cos(L / (2 R_min))) further from the kerb for L of room ahead (3 cm at 0.76
//   m). Repeated until the lane check's footprint has 0.3 m on the kerb side (at most 8 times,
//   each gaining 1 cm or more), then 1. and 2. as above. Where it still gets stuck (or got stuck
//   otherwise: "turned across the road" on a single road lane), once more creeping to 0.6 m of
//   room: from further out less turn passes the car ahead, and the exit then fits the lane. A start
//   with less than 0.2 m of room on the kerb side creeps first (the shunts without get stuck
//   there almost always), then tries without, then creeps to 0.6 m. Where one of those got stuck
//   turned across the road, last without creeping and with creeping to 0.6 m, with moves of at
//   most 5 degrees, then 3 degrees (the exit is tried after every reverse move: large moves can
//   turn the vehicle past the few turns whose exit both clears the car ahead and fits a single
//   lane round a tight bend).
// "Just clear": every pose of a move keeps the footprint (expanded by
// lane_departure_check_expansion_margin, and 1 cm) inside the lanes and at least the smallest
// collision margin plus 2 cm from every static obstacle (sampled every 2 cm at most and bisected
// to 0.1 mm where a move ends). The moves and the exit are then checked again densely
// (conservative advancement: steps of (clearance - floor) / L, L = 1 + curvature x the
// footprint's bounding radius, at least 1 cm) against the smallest margin plus 1 cm. A move that
// gets less than 1 cm is a dead end. Output: one partial path per move (forward at
// geometric_pull_out_velocity, reverse at |backward_velocity|, each capped at what
// maximum_longitudinal_acc reaches over half the move; velocity 0 at its end, points every 10 cm),
// then the S as above.
#pragma once

#include "pullout/lane_planners/pull_out_planner.hpp"

namespace pullout {

class GeometricPullOut final : public PullOutPlanner {
 public:
  PlannerType type() const override { return PlannerType::kGeometric; }
  PlannerCandidates plan(const PlanningContext& context, const Pose2& start, const StopCondition& stop) const override;
  // The shunting manoeuvre (see the top of this file): one candidate, or a failure saying where it
  // got stuck. Empty (no failure) when geometric_pull_out_max_shunts is 0.
  PlannerCandidates plan_multi_move(const PlanningContext& context, const Pose2& start,
                                    const StopCondition& stop) const override;
};

}  // namespace pullout
