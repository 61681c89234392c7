// The start planner pipeline: validate a request, build the world, search the planners over the
// collision-margin ladder, and return a path (or a stop path with every attempt's reason).
//
//   request -> validate -> world (lanes, static objects) -> for each margin in
//   collision_check_margins: for each planner in search_priority: plan, check lane departure and
//   static collision -> first success -> velocities -> PullOutPath. Nothing found: each
//   planner's multi-move manoeuvre from the ego pose at the smallest margin (the geometric
//   planner's shunting, geometric_pull_out_max_shunts > 0; evaluation-table detail "shunting").
//   Still nothing and freespace_planner.enable_freespace_planner: the freespace pull-out (hybrid
//   A*) from the ego pose and, when that finds nothing (and enable_back), from the backward start
//   candidates in order of their distance (a straight reverse to the candidate, a stop, then the
//   freespace path; its end poses ahead of the candidate): one freespace_planner.time_limit for
//   all of them, the current pose first, so that what succeeds from it today is unchanged. The
//   same when freespace is listed in search_priority (one budget over its candidates). A request
//   with an occupancy grid and no lanes (allowed when the freespace planner is enabled) is a pure
//   freespace problem: hybrid A* straight to the goal pose.
//
// Thread safety: StartPlanner is immutable after construction; plan() may be called concurrently
// from several threads. Failure modes are values, never exceptions: an invalid request gives
// Outcome::kRejected with one issue per problem (naming the field), "no path" gives
// Outcome::kNoPath with a stop path and the reasons, and a search cut short by the stop condition
// gives kNoPath with `stopped` set (timed_out = true for the deadline). Each evaluation-table row
// carries a typed AttemptOutcome and a detail.
//
// Lanes come either inline (request.lanes) or from the Lanelet2 map given at construction:
// request.route_lanelet_ids then names the road lanelets to pull out onto, and the pipeline plans
// on the lanes select_map_lanes (maps/map_lanes.hpp) picks around the vehicle. A request with
// route ids and no map, or with both lanes and route ids, is rejected.
//
// Bounded work: whatever the coordinates, the lanes (inline or from the map) are cropped to the
// planning horizon (planning_horizon_m, a square around the ego pose; lanes/lane_crop.hpp) and the
// static objects to those that may reach into it, before the lane world is built. What the crop
// keeps is bounded by RequestLimits (max_horizon_lane_length_m; max_coordinate_m for every
// coordinate). Every build step that grows with the input (lane world, costmap, heuristic) checks
// the stop condition inside, so a deadline or cancellation is honoured before the first attempt.
// A request whose road lies beyond the horizon is rejected ("lanes: no lane of subtype road within
// the planning horizon (...)").
#pragma once

#include <cstddef>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "pullout/model/types.hpp"
#include "pullout/pipeline/parameters.hpp"
#include "pullout/pipeline/published_path.hpp"
#include "pullout/search/stop_condition.hpp"
#include "pullout/vehicle/vehicle_info.hpp"

namespace pullout {

class LaneletMap;
class LaneWorld;

// "field: problem" lines joined by '\n'.
std::string format_issues(const std::vector<RequestIssue>& issues);

// The world a search planned on: the lanes (the request's inline lanes, or those picked on the map
// for its route) and the request's objects. The safety checks of a found path use exactly these.
struct PlannedWorld {
  std::vector<Lane> lanes;
  std::vector<Object> objects;
  VehicleInfo vehicle;  // the vehicle planned for (StartPlanner::vehicle_for)
  // The complete lane world plan() built from `lanes` (or reused, see plan()); null when it built
  // none (a grid-only request, a build cut short, planned_world()). Immutable, so the safety
  // monitor of a found path and a later request's search may share it across threads.
  std::shared_ptr<const LaneWorld> lane_world;
};

struct PlanningResult {
  enum class Outcome { kFound, kNoPath, kRejected };
  Outcome outcome{Outcome::kNoPath};
  // kFound: the path. kNoPath: a stop path at the ego pose (all velocities 0, found = false,
  // reasons filled). kRejected: empty.
  PullOutPath path;
  std::vector<PlannerAttempt> evaluation_table;  // one row per attempt, in search order
  std::string stop_reason;                       // kNoPath: one line summary
  std::vector<RequestIssue> issues;              // kRejected
  // kFound: how the published path ends (finish_published_path): where it stops before an object
  // beyond the end pose, or that it is clear; `path_end.note` is also the last of path.reasons.
  PublishedPathEnd path_end;
  // Why the search was cut short before it was done: kDeadline or kCancelled (the caller's stop
  // condition; a planner's own budget only ends that planner's attempt), kNone otherwise.
  StopReason stopped{StopReason::kNone};
  bool timed_out{false};  // stopped == kDeadline
  double planning_time_ms{0.0};
  // kFound and kNoPath: what was planned on (lanes empty for a grid-only request). Null: kRejected.
  std::shared_ptr<const PlannedWorld> world;
};

// [m] Half the side of the square around the ego pose that a plan with these parameters can reach:
// the largest of (forward_path_length + freespace_planner.end_pose_search_end_distance +
// path_safety_check.target_filtering.object_check_forward_distance: the path ahead and the safety
// check's look ahead of the vehicle on it), (max_back_distance + 5 m of road kept behind +
// object_check_backward_distance: the reverse and the look back), the freespace costmap window to
// its corner, and surround_moving_obstacle_check.search_radius; plus the vehicle's length, the
// largest collision margin and 50 m for the lateral offset to the road. About 397 m with the
// defaults. A path never leaves this square (its arc length is bounded), so cropping to it changes
// no plan.
double planning_horizon_m(const StartPlannerParameters& parameters, const VehicleInfo& vehicle);

// Named vehicles a request may ask for (PullOutRequest::vehicle_profile), e.g. "car", "van", "bus".
using VehicleProfiles = std::map<std::string, VehicleInfo>;
// The longest vehicle_profile [bytes] looked up; a longer one is rejected unread.
inline constexpr std::size_t kMaxVehicleProfileBytes = 255;

class StartPlanner {
 public:
  // Parameters, vehicle and profiles must be valid (as load_config / check_config accept them).
  // `map` may be null (no map: only inline lanes are accepted). `vehicle` is the default vehicle;
  // a request may name one of `profiles` or carry its own dimensions (vehicle_for).
  StartPlanner(VehicleInfo vehicle, StartPlannerParameters parameters, RequestLimits limits = {},
               std::shared_ptr<const LaneletMap> map = nullptr, VehicleProfiles profiles = {});

  // Plans for one request within `stop` (checked before every attempt and inside every search).
  // Applies the request's overrides (search_priority, search_policy) to a copy of the parameters.
  // Never throws for bad input.
  // `previous`: a world an earlier plan() returned (the vehicle's previous request), or null. When
  // this request's lanes, after cropping, are bit for bit that world's lanes (identical_lanes), its
  // lane world is used instead of building the same one again: the result is the same, only the
  // build's time is saved (a vehicle re-sending its request with new poses and the same lanes).
  PlanningResult plan(const PullOutRequest& request, const StopCondition& stop,
                      const PlannedWorld* previous = nullptr) const;

  // Only the validation step of plan(): every problem of the request, empty when valid.
  std::vector<RequestIssue> validate(const PullOutRequest& request) const;
  // A progress sample's problems ("progress.velocity_mps: |speed| 1e+300 exceeds 100 m/s"), empty when its
  // pose and speed are within the limits.
  std::vector<RequestIssue> validate(const ExecutionProgress& progress) const;

  // The request's vehicle problems: both a profile and dimensions, an unknown profile
  // ("vehicle_profile: unknown profile 'x' (the service has bus, car, van)"), each dimension outside
  // kVehicleFields' range ("vehicle.wheel_base: must be in [0.1, 20] m, got 0"). Part of validate().
  std::vector<RequestIssue> vehicle_issues(const PullOutRequest& request) const;
  // The vehicle a (valid) request is planned for: its own dimensions, else its profile, else the
  // default vehicle.
  VehicleInfo vehicle_for(const PullOutRequest& request) const;

  // The world plan() plans `request` on (its lanes, inline or picked on the map, and its objects),
  // without planning: what a session restored from a snapshot (VehicleSession::restore) checks
  // safety on. Null with `issues` filled when the request is not valid.
  std::shared_ptr<const PlannedWorld> planned_world(const PullOutRequest& request,
                                                    std::vector<RequestIssue>& issues) const;

  // The default vehicle.
  const VehicleInfo& vehicle() const { return vehicle_; }
  const VehicleProfiles& profiles() const { return profiles_; }
  const StartPlannerParameters& parameters() const { return parameters_; }
  const RequestLimits& limits() const { return limits_; }
  const std::shared_ptr<const LaneletMap>& map() const { return map_; }

 private:
  bool grid_only_allowed() const;
  // A request with a grid and no lanes: hybrid A* straight to the goal pose.
  PlanningResult plan_grid_only(const PullOutRequest& request, const VehicleInfo& vehicle,
                                const StopCondition& stop) const;

  VehicleInfo vehicle_;
  StartPlannerParameters parameters_;
  RequestLimits limits_;
  std::shared_ptr<const LaneletMap> map_;
  VehicleProfiles profiles_;
};

}  // namespace pullout
