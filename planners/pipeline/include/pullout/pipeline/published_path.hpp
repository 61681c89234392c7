// The last step before a found path leaves the pipeline: every published point is checked against
// the static obstacles, and the path stops before the first one it would reach beyond the end pose.
//
// The planners check their own section (the pull-out up to the end pose, plus
// shift_collision_check_distance_from_end or the turns' collision distance from the end), then
// extend the path along the road centerline to the goal or forward_path_length without checking
// it. A vehicle drives what is published, so finish_published_path():
//
//   - checks the footprint at every point of every partial path with the pipeline's ObjectChecker
//     (the same FCL checker the planners use): up to the end pose for contact (the planners have
//     kept their margin there), beyond the end pose for the collision margin the path was found
//     with (or the clearance at the end pose when that is smaller: freespace's margin comes from
//     its rasterised costmap and is not exact in FCL terms);
//   - at the first point that fails, ends the path: its partial path ends at the farthest pose
//     before that point which still passes (bisection on the straight piece between the two
//     points, to 1 cm), later partial paths and their pairs are dropped, and the velocities of
//     that partial path are capped so that the vehicle stops exactly there: at a point r metres
//     before the stop the speed is at most the highest one from which a stop with deceleration
//     <= max_deceleration and jerk <= max_jerk (starting from zero deceleration) needs at most r.
//     The last point has velocity 0; deceleration along the ramp never exceeds max_deceleration
//     and falls to 0 at the stop.
//   - too close to stop within the limits: the ramp still ends at the same stop (the end of the
//     published path is the stop), it starts earlier, before the end pose if need be, so the
//     speed at the end pose is below the planned terminal velocity; the pair of that partial path
//     gets the lowered velocity and `stop_within_limits` is false. The note says so.
//   - nothing in the way: the path is unchanged. It ends where the planner ended it: at the goal
//     (velocity 0) when the goal lies on the road centerline within forward_path_length of the
//     start, else forward_path_length along the road centerline after the start (or at the end
//     of the road lanes), at the lane's speed limit (the vehicle re-requests before it gets there).
//
// The result says how the path ends, with a note for people ("stops 2.00 m before object 7,
// 21.3 m beyond the end pose; ..."), which the pipeline appends to PullOutPath::reasons and
// keeps in PlanningResult::path_end.
#pragma once

#include <cstdint>
#include <string>

#include "pullout/model/types.hpp"

namespace pullout {

class ObjectChecker;  // pullout/collision/object_checker.hpp (not included: this header reaches
                      // the CLI through start_planner.hpp, without Eigen or FCL)

struct PublishedPathLimits {
  double margin_m{0.0};               // [m] clearance kept beyond the end pose (the attempt's margin)
  double max_deceleration_mps2{1.0};  // [m/s^2] > 0, of the stop (stop_condition.*)
  double max_jerk_mps3{1.0};          // [m/s^3] > 0
};

struct PublishedPathEnd {
  // true: the path was cut and stops (velocity 0 at its last point) before `object_id`.
  bool stops_before_object{false};
  std::int64_t object_id{0};
  double clearance_m{0.0};  // footprint clearance at the stop, to the nearest obstacle [m]
  // Path length from the end pose to the last published point [m]; negative when the path stops
  // before the end pose (an obstacle the planner's own checks missed).
  double beyond_end_pose_m{0.0};
  // false: the planned velocity at the end pose was too high to stop within the limits; the ramp
  // starts earlier and the end-pose velocity (and the pair) were lowered.
  bool stop_within_limits{true};
  std::string note;  // one line for people: how the published path ends
};

// Checks and, where needed, cuts `path` (a found path whose end_pose is a point of its last
// partial path) in place. Never throws; a path with no points is returned unchanged.
PublishedPathEnd finish_published_path(PullOutPath& path, const ObjectChecker& objects,
                                       const PublishedPathLimits& limits);

// [m] distance needed to stop from `speed` [m/s] with deceleration <= max_deceleration and jerk <=
// max_jerk, starting from zero deceleration and ending at zero deceleration.
double jerk_limited_stop_distance(double speed, double max_deceleration, double max_jerk);

}  // namespace pullout
