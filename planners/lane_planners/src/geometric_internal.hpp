// Internal: the geometric planner's two-arc S candidates, shared by its single-move plan() and its
// shunting manoeuvre (geometric_shunts.cpp), which tries the S from each pose it reaches.
#pragma once

#include <cmath>

#include <vector>

#include "pullout/geometry/curvature_path.hpp"
#include "pullout/lane_planners/pull_out_planner.hpp"

namespace pullout {

// How far [m] a footprint corner at (along, across) from base_link - `along` ahead (> 0) or behind,
// `across` > 0 outwards on the side away from the arc's centre - gets beyond its start across a
// line (a lane edge) at `tilt` [rad] to the vehicle - the vehicle already turned by `tilt` the
// way the arc turns, 0 when parallel - while the vehicle turns by `turn` [rad] on an arc of radius
// r: the corner circles the centre at rho = hypot(r + across, along), its distance beyond the
// line's parallel through the centre is rho cos(t + tilt - peak) after a turn t, peak =
// atan(along / (r + across)); it grows until t = peak - tilt, and not at all once tilt >= peak.
inline double corner_swing(double r, double along, double across, double turn, double tilt = 0.0) {
  const double u = r + across;
  const double radius = std::hypot(u, along);
  const double peak = std::atan2(along, u);
  const double at_start = radius * std::cos(tilt - peak);
  if (tilt >= peak) return 0.0;
  return (turn >= peak - tilt ? radius : radius * std::cos(turn + tilt - peak)) - at_start;
}

// The largest expansion [m], up to `cap`, of the side `side` of `base` with which the footprint at
// `pose` stays inside the lanes, by `bisections` halvings of [0, cap]; -1 when `base` itself does
// not. Shared by the S's lane-check footprint (the room at the front, the rear and the kerb side)
// and the shunts' creeping (the room on the kerb side).
double side_clearance(const LaneWorld& world, const Footprint& base, double Footprint::*side, const Pose2& pose,
                      double cap, int bisections);

// The S candidates from `start` (see geometric_pull_out.hpp), tightest end pose first. With a
// finite `usable_margin` [m] the search ends at the first candidate usable at that margin (no
// rejection, clearance >= usable_margin); +inf: every candidate. With `turn_paths`, the arcs of
// each candidate are appended to it (an empty path for a candidate with none). With
// `turn_candidates`, two turns at R_min joined by a 0..9 m tangent follow the S candidates.
PlannerCandidates arc_pair_candidates(const PlanningContext& context, const Pose2& start, const StopCondition& stop,
                                      double usable_margin, std::vector<CurvaturePath>* turn_paths,
                                      bool turn_candidates);

}  // namespace pullout
