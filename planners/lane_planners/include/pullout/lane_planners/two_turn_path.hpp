// Two turns joined by a common tangent: the shape of both the geometric (arc turns) and the
// clothoid (clothoid-arc-clothoid turns) pull-out. From a start pose, the first turn heads towards
// the road, an optional straight follows, and the second turn brings the vehicle onto the road
// centerline with the centerline's heading.
//
// The unknown is the first turn's heading change d1 (the second is what is left to reach the
// centerline's heading). It is found as the root of the end point's lateral offset from the
// centerline, bracketed from the two-arc closed form 2R(1 - cos d) + l sin d = offset when the
// start is parallel to the road, or by scanning d1 otherwise, then refined with the Illinois
// method on the exact path. Because the target heading depends on where the path ends (curved
// roads), the solve is repeated with the heading at the previous end until it settles.
#pragma once

#include <optional>

#include "pullout/geometry/curvature_path.hpp"
#include "pullout/geometry/polyline.hpp"

namespace pullout {

struct TwoTurnSpec {
  double kappa{0.2};      // [1/m] peak curvature of the turns
  double sharpness{0.0};  // [1/m^2] curvature rate; <= 0: circular arcs
  double straight{0.0};   // [m] common tangent between the turns
};

struct TwoTurnPath {
  CurvaturePath path;
  std::size_t first_turn_pieces{0};  // pieces of the first turn (the path splits after them)
  double lateral_error{0.0};         // [m] end point to the centerline
  double heading_error{0.0};         // [rad] end heading minus the centerline's
};

// `centerline` should be a local window of the road centerline around the start (projection is
// linear in its size). nullopt when no root exists (the start is too close to the centerline for
// these turns, or the turns cannot reach it going forward).
std::optional<TwoTurnPath> solve_two_turn(const Pose2& start, const Polyline& centerline, const TwoTurnSpec& spec);

// Two circular arcs turning opposite ways (an S) from `start` exactly to `end` (position and
// heading), as in Vorobieva et al. (IFAC 2013): the first arc has radius `first_radius` [m] and
// turns towards the side `end` lies on; the second arc's radius is solved so that the arcs are
// tangent where they meet. With C1 the first centre (first_radius beside `start`), n the unit
// normal at `end` towards the second centre and D = C1 - end:
//   R2 = (|D|^2 - R1^2) / (2 (R1 + D . n)).
// nullopt when the end is straight ahead of or behind the start, when no such S moving forward
// exists (an arc would turn by pi or more, or R2 <= 0), or when R2 < `min_radius` [m].
// `first_side` +1 / -1 makes the first arc turn left / right whichever side of the start's heading
// the end lies on (0: towards that side). A start already turned towards the road, with the end
// on a road bending back the other way, lies beside the end's side of its own heading line: the S
// that leaves it as Autoware's does still turns towards the road first, then straightens.
std::optional<TwoTurnPath> solve_arc_pair(const Pose2& start, const Pose2& end, double first_radius, double min_radius,
                                          double first_side = 0.0);

}  // namespace pullout
