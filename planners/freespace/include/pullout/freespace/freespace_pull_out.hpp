// The freespace pull-out: a hybrid A* path (hybrid_astar.hpp) out of a spot the lane-based
// planners cannot leave (boxed in between cars, a parking lot), to an end pose on the road lane
// ahead, joined to the road centerline.
//
// As in Autoware's start planner (freespace_planner.*):
//  - costmap: the request's occupancy grid (values >= costmap_configs.obstacle_threshold or
//    unknown are obstacles), else the lanes (drivable) and the static objects rasterised at
//    costmap_configs.resolution over a window around the vehicle; static objects are added to a
//    grid too;
//  - vehicle: the footprint grown by vehicle_shape_margin (half on each side) where the start
//    pose allows it: each side grows by half the margin, or by the room the start has on that
//    side less 1 cm when that is less (a car 0.15 m from the kerb, 0.4 m from the car ahead).
//    Autoware's default margin (1.0 m, meant for open lots) otherwise puts the start of a car
//    parked at a kerb in collision; the search keeps the clamped margin everywhere. Steering
//    limited to max_steer_angle x max_turning_ratio;
//  - end poses: on the road centerline from s(start) + end_pose_search_start_distance to
//    s(start) + end_pose_search_end_distance every end_pose_search_interval; the first one reached
//    wins. The start is the current pose, or (unlike Autoware, whose freespace pull-out plans
//    from the current pose only) a backward start candidate when the current pose fails: see
//    StartPlanner::plan (start_planner.hpp);
//  - output: the path split at every change of direction (the cusp point ends one partial path
//    and starts the next), +/- velocity on the points and 0 at every cusp; the last forward
//    partial path trimmed within 1 m of the end pose when the search stopped in the goal region
//    (not exactly on the end pose) and continued on the road centerline; unlike Autoware, one
//    velocity/acceleration pair per partial path.
//
// Failure modes are values: PlannerCandidates::failure is the search's status as an attempt
// outcome (attempt_outcome) with the end pose in the detail. The search budget is
// freespace_planner.time_limit (StopReason::kBudget), added to the caller's stop condition: the
// deadline and cancellation end it too.
#pragma once

#include <string>
#include <vector>

#include "pullout/freespace/costmap.hpp"
#include "pullout/freespace/freespace_parameters.hpp"
#include "pullout/freespace/freespace_search.hpp"
#include "pullout/freespace/hybrid_astar.hpp"
#include "pullout/lane_planners/pull_out_planner.hpp"

namespace pullout {

class FreespacePullOut : public PullOutPlanner {
 public:
  // `rrt_star`: the search of freespace_planner_algorithm "rrtstar" (freespace_ompl's
  // plan_rrt_star); std::invalid_argument when that algorithm is asked for without it.
  explicit FreespacePullOut(const FreespaceParameters& parameters, FreespaceSearch rrt_star = {});
  PlannerType type() const override { return PlannerType::kFreespace; }
  // One candidate at most, from `start`: the current pose (context.ego) or a backward start
  // candidate (the pipeline puts the straight reverse to it in front of the path). The end poses
  // are measured from s(start); the costmap's window stays centred on the current pose.
  PlannerCandidates plan(const PlanningContext& context, const Pose2& start, const StopCondition& stop) const override;

 private:
  FreespaceParameters parameters_;
  FreespaceSearch rrt_star_;
};

// [m] With freespace_planner_algorithm rrtstar, FreespacePullOut grows the objects in its costmap
// by this (the smallest of Autoware's default collision_check_margins): RRT*'s paths, shortest
// between its samples, run along the obstacles, and the pipeline asks at least this clearance to
// the objects of a path. Where the start is closer than that to an object (its footprint, with
// the start-aware margin, collides), the objects are not grown. Hybrid A* searches the plain
// costmap (its paths kept this clearance on every scenario, its figures are with it).
constexpr double kRrtStarObjectClearance = 0.1;

// Each polygon grown by `d` [m] on every side, conservatively: the convex hull of its vertices
// moved by +-d in x and y (for a convex polygon a superset of the points within d of it; a
// polygon that is not convex becomes its grown hull).
std::vector<Polygon> grown_obstacles(const std::vector<Polygon>& obstacles, double d);

// The search freespace_planner_algorithm names: hybrid A* for "astar", `rrt_star` for "rrtstar"
// (std::invalid_argument when it is empty, or for another name).
FreespaceSearch freespace_search(const FreespaceParameters& parameters, const FreespaceSearch& rrt_star);

// The search settings the freespace parameters imply for this vehicle.
HybridAStarConfig freespace_search_config(const VehicleInfo& vehicle, const FreespaceParameters& parameters);
// The vehicle footprint grown by vehicle_shape_margin (half on each side).
Footprint freespace_footprint(const VehicleInfo& vehicle, const FreespaceParameters& parameters);
// The same, each side's growth clamped to the room the footprint has on that side at `start` on
// `costmap` less 1 cm (never below 0): the pull-out's footprint (see the file comment).
Footprint freespace_footprint(const VehicleInfo& vehicle, const FreespaceParameters& parameters, const Costmap& costmap,
                              const Pose2& start);

// [m] Half the side of the costmap's square window around the vehicle: the farthest end pose,
// the vehicle's length and 10 m more.
double freespace_window_half_size(const FreespaceParameters& parameters, const VehicleInfo& vehicle);

// The costmap of a request: the grid with the obstacles added, or (grid == nullptr) the lanes of
// `world` and the obstacles over the square window of half size `half_window` [m] around
// `centre`, clipped to the lanes' bounding box. Built within `stop` (Costmap::stopped() tells
// whether it cut the build short: such a costmap is not to be searched).
Costmap freespace_costmap(const FreespaceParameters& parameters, const OccupancyGrid* grid, const LaneWorld* world,
                          const std::vector<Polygon>& obstacles, const Pose2& centre, double half_window,
                          const StopCondition& stop = {});

// Waypoints -> partial paths split at every change of direction: velocity direction x velocity,
// 0 on the last point of each partial path; one pair per partial path ({+/-v, +/-v^2 / L}: v
// reached at half of it, stopped at its end).
struct SplitPath {
  std::vector<PathWithLaneId> partial_paths;
  std::vector<TerminalVelocityAccel> pairs;
  std::vector<int> directions;  // per partial path
};
SplitPath split_at_cusps(const std::vector<Waypoint>& waypoints, double velocity);

// The attempt outcome of a search status: start occupied -> kStartInvalid, goal occupied ->
// kGoalInvalid, timeout, cancelled, node limit and no path -> the same.
AttemptOutcome attempt_outcome(HybridAStarResult::Status status);

// A pure freespace problem (no lanes): from start straight to goal on the costmap, within
// `stop` and freespace_planner.time_limit.
struct FreespaceGoalResult {
  HybridAStarResult::Status status{HybridAStarResult::Status::kNoPath};
  StopReason stopped{StopReason::kNone};  // why the search was cut short, if it was
  std::size_t expansions{0};              // search work done (hybrid A* expansions)
  PullOutPath path;                       // found: partial paths to the goal (end_pose = goal)
};
FreespaceGoalResult plan_freespace_to_goal(const Costmap& costmap, const VehicleInfo& vehicle,
                                           const FreespaceParameters& parameters, const Pose2& start, const Pose2& goal,
                                           const StopCondition& stop, const FreespaceSearch& rrt_star = {});

}  // namespace pullout
