#include "pullout/pipeline/start_planner.hpp"

#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <sstream>

#include "pullout/collision/footprint.hpp"
#include "pullout/collision/object_checker.hpp"
#include "pullout/freespace/freespace_pull_out.hpp"
#include "pullout/freespace_ompl/rrt_star.hpp"
#include "pullout/lane_planners/clothoid_pull_out.hpp"
#include "pullout/lane_planners/geometric_pull_out.hpp"
#include "pullout/lane_planners/shift_pull_out.hpp"
#include "pullout/lanes/lane_crop.hpp"
#include "pullout/lanes/lane_world.hpp"
#include "pullout/maps/lanelet_map.hpp"
#include "pullout/maps/map_lanes.hpp"
#include "pullout/model/names.hpp"
#include "start_candidates.hpp"
#include "validation.hpp"

namespace pullout {

namespace {

// [m] Road kept behind the start beyond max_back_distance (Autoware's backward_path_length).
constexpr double kBackwardPathLength = 5.0;
// [m] A route passing farther than this from the start is not the one to pull out onto.
constexpr double kMaxRouteDistance = 10.0;

// [m] Added to the farthest reach of the planners and checks: the lateral offset of the vehicle
// from the road centerline, lane widths, and the footprint's reach beyond a path point.
constexpr double kHorizonSlack = 50.0;

// The lanes one request plans on: its inline lanes, or those picked on the map for its route (with
// the road and pull-out lanes in driving order), cropped to the planning horizon.
struct RequestLanes {
  std::vector<Lane> lanes;
  std::vector<std::int64_t> road_ids;      // map requests: the road lanes
  std::vector<std::int64_t> pull_out_ids;  // map requests: the shoulder lanes (empty: the road)
  std::vector<RequestIssue> issues;
};

std::string format_length(double m) {
  std::ostringstream os;
  os << m;
  return os.str();
}

double bounds_length(const std::vector<Lane>& lanes) {
  double total = 0.0;
  for (const Lane& lane : lanes) total += polyline_length(lane.left_bound) + polyline_length(lane.right_bound);
  return total;
}

// Distance [m] from p to the outline of a lane (its bounds and their end joints).
double distance_to_lane(const Lane& lane, const Vec2& p) {
  Polygon ring;
  for (const Point2& q : lane.left_bound) ring.push_back(to_vec(q));
  for (auto it = lane.right_bound.rbegin(); it != lane.right_bound.rend(); ++it) ring.push_back(to_vec(*it));
  double d = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < ring.size(); ++i)
    d = std::min(d, distance_to_segment(p, ring[i], ring[(i + 1) % ring.size()]));
  return d;
}

// Of `ids` (driving order), those whose lane the crop kept, cut to the run of consecutive kept ones
// holding the lane nearest to `ego`: a chain that leaves the horizon and comes back is not joined
// across the gap.
std::vector<std::int64_t> kept_run(const std::vector<std::int64_t>& ids, const std::vector<Lane>& kept,
                                   const Vec2& ego) {
  const auto lane_of = [&](std::int64_t id) -> const Lane* {
    for (const Lane& l : kept) {
      if (l.id == id) return &l;
    }
    return nullptr;
  };
  std::size_t nearest = ids.size();
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < ids.size(); ++i) {
    const Lane* l = lane_of(ids[i]);
    if (l == nullptr) continue;
    const double d = distance_to_lane(*l, ego);
    if (d < best) {
      best = d;
      nearest = i;
    }
  }
  if (nearest == ids.size()) return {};
  std::size_t first = nearest;
  while (first > 0 && lane_of(ids[first - 1]) != nullptr) --first;
  std::size_t last = nearest;
  while (last + 1 < ids.size() && lane_of(ids[last + 1]) != nullptr) ++last;
  return {ids.begin() + static_cast<std::ptrdiff_t>(first), ids.begin() + static_cast<std::ptrdiff_t>(last) + 1};
}

RequestLanes request_lanes(const PullOutRequest& request, const LaneletMap* map, const VehicleInfo& vehicle,
                           const StartPlannerParameters& params, const RequestLimits& limits) {
  RequestLanes out;
  const bool from_map = has_route(request) && map != nullptr;
  MapLanes selected;
  if (from_map) {
    MapLaneOptions options;
    options.backward_length_m = kBackwardPathLength + params.max_back_distance;
    options.forward_length_m = params.forward_path_length;
    options.start_tolerance_m = vehicle.width_m() / 2.0;
    options.max_route_distance_m = kMaxRouteDistance;
    selected = select_map_lanes(*map, request, options);
    if (!selected.issues.empty()) {
      out.issues = std::move(selected.issues);
      return out;
    }
  }
  const std::vector<Lane>& all = from_map ? selected.lanes : request.lanes;
  const double horizon = planning_horizon_m(params, vehicle);
  CroppedLanes cropped = crop_lanes(all, horizon_square(request.ego_pose.x, request.ego_pose.y, horizon));
  const std::string field =
      from_map ? (request.route_segments.empty() ? "route_lanelet_ids" : "route_segments") : "lanes";
  const std::string where = " within the planning horizon (" + format_length(horizon) + " m around ego_pose)";
  const double kept_length = bounds_length(cropped.lanes);
  if (kept_length > limits.max_horizon_lane_length_m) {
    out.issues.push_back({field, format_length(kept_length) + " m of lane bounds" + where + " exceed the limit of " +
                                     format_length(limits.max_horizon_lane_length_m) + " m"});
    return out;
  }
  out.lanes = std::move(cropped.lanes);
  if (from_map) {
    out.road_ids = kept_run(selected.road_ids, out.lanes, to_vec(request.ego_pose));
    out.pull_out_ids = kept_run(selected.pull_out_ids, out.lanes, to_vec(request.ego_pose));
    if (out.road_ids.empty()) out.issues.push_back({field, "no road lanelet of the route" + where});
  } else if (std::none_of(out.lanes.begin(), out.lanes.end(),
                          [](const Lane& l) { return l.subtype == LaneSubtype::kRoad; })) {
    out.issues.push_back({field, "no lane of subtype road" + where});
  }
  return out;
}

std::vector<std::size_t> indices_of(const LaneWorld& world, const std::vector<std::int64_t>& ids) {
  std::vector<std::size_t> out;
  for (std::int64_t id : ids) {
    if (const auto i = world.find(id)) out.push_back(*i);
  }
  return out;
}

const std::vector<PlannerType>& available_planners() {
  static const std::vector<PlannerType> kAvailable(kSearchPlanners.begin(), kSearchPlanners.end());
  return kAvailable;
}

std::unique_ptr<PullOutPlanner> make_planner(PlannerType type, const StartPlannerParameters& parameters) {
  switch (type) {
    case PlannerType::kShift:
      return std::make_unique<ShiftPullOut>();
    case PlannerType::kGeometric:
      return std::make_unique<GeometricPullOut>();
    case PlannerType::kClothoid:
      return std::make_unique<ClothoidPullOut>();
    case PlannerType::kFreespace:
      return std::make_unique<FreespacePullOut>(parameters.freespace_planner, &plan_rrt_star);
    default:
      return nullptr;
  }
}

std::string format_margin(double m) {
  std::ostringstream os;
  os.setf(std::ios::fixed);
  os.precision(2);
  os << m;
  return os.str();
}

// The start pose must lie on a lane; a vehicle half a width outside still counts (it may stand
// partly on the kerb), further away it is not on this request's lanes at all. `inside`: whether the
// lanes contain the ego position (LaneWorld::contains, or lanes_contain without a world).
// O(vertices) beyond that.
std::optional<RequestIssue> check_start_on_lanes(const std::vector<Lane>& lanes, bool inside, const Pose2& ego,
                                                 const VehicleInfo& v) {
  if (inside) return std::nullopt;
  const Vec2 p = to_vec(ego);
  double nearest = std::numeric_limits<double>::infinity();
  std::int64_t nearest_id = 0;
  for (const Lane& lane : lanes) {
    const Polygon poly = bounds_polygon(lane);
    for (std::size_t i = 0; i < poly.size(); ++i) {
      const double d = distance_to_segment(p, poly[i], poly[(i + 1) % poly.size()]);
      if (d < nearest) {
        nearest = d;
        nearest_id = lane.id;
      }
    }
  }
  if (nearest <= v.width_m() / 2.0) return std::nullopt;
  std::ostringstream os;
  os.setf(std::ios::fixed);
  os.precision(2);
  os << "(" << ego.x << ", " << ego.y << ") is on no lane; the nearest, lane " << nearest_id << ", is " << nearest
     << " m away";
  return RequestIssue{"ego_pose", os.str()};
}

PullOutPath make_stop_path(const PullOutRequest& request) {
  PullOutPath path;
  path.found = false;
  path.planner_type = PlannerType::kStop;
  PathWithLaneId stop;
  PathPoint point;
  point.pose = request.ego_pose;
  point.longitudinal_velocity_mps = 0.0;
  stop.points = {point, point};
  path.partial_paths.push_back(std::move(stop));
  path.pairs_terminal_velocity_and_accel.push_back({0.0, 0.0});
  path.start_pose = request.ego_pose;
  path.end_pose = request.ego_pose;
  return path;
}

// One line per planner: the outcomes at the last margin tried (the least demanding one).
std::vector<std::string> no_path_reasons(const std::vector<PlannerAttempt>& attempts) {
  std::vector<std::string> reasons;
  if (attempts.empty()) return reasons;
  const double last_margin = attempts.back().margin_m;
  for (const PlannerAttempt& a : attempts) {
    if (a.planner == PlannerType::kNone || a.margin_m != last_margin) continue;
    reasons.push_back(std::string(to_string(a.planner)) + " at margin " + format_margin(a.margin_m) + " m, backward " +
                      format_margin(a.backward_distance_m) + " m: " + describe(a));
  }
  return reasons;
}

// Every published point checked against the static objects; the path stops before the first one
// beyond the end pose (published_path.hpp), and says how it ends.
void publish_checked(PlanningResult& result, const ObjectChecker& objects, double margin,
                     const StartPlannerParameters& params) {
  const PublishedPathLimits limits{margin, params.stop_condition.maximum_deceleration_for_stop,
                                   params.stop_condition.maximum_jerk_for_stop};
  result.path_end = finish_published_path(result.path, objects, limits);
  if (!result.path_end.note.empty()) result.path.reasons.push_back(result.path_end.note);
}

// The static objects of a grid-only request, for the final check of its path.
ObjectChecker static_obstacle_checker(const PullOutRequest& request, const VehicleInfo& vehicle,
                                      const StartPlannerParameters& params) {
  std::vector<Obstacle> obstacles;
  for (const Object& o : request.objects) {
    if (std::abs(o.velocity_mps) >= params.th_moving_object_velocity) continue;
    if (!params.object_types_to_check_for_path_generation.includes(o.object_class)) continue;
    obstacles.push_back({o.id, object_polygon(o)});
  }
  return ObjectChecker(vehicle_footprint(vehicle), std::move(obstacles));
}

}  // namespace

bool planner_available(PlannerType type) {
  const auto& a = available_planners();
  return std::find(a.begin(), a.end(), type) != a.end();
}

StartPlanner::StartPlanner(VehicleInfo vehicle, StartPlannerParameters parameters, RequestLimits limits,
                           std::shared_ptr<const LaneletMap> map, VehicleProfiles profiles)
    : vehicle_(vehicle),
      parameters_(std::move(parameters)),
      limits_(limits),
      map_(std::move(map)),
      profiles_(std::move(profiles)) {}

std::vector<RequestIssue> StartPlanner::vehicle_issues(const PullOutRequest& request) const {
  std::vector<RequestIssue> issues;
  if (!request.vehicle_profile.empty()) {
    if (request.vehicle) {
      issues.push_back({"vehicle_profile", "give a vehicle profile or the vehicle's dimensions (vehicle), not both"});
    }
    if (request.vehicle_profile.size() > kMaxVehicleProfileBytes) {
      issues.push_back(
          {"vehicle_profile", "longer than " + std::to_string(kMaxVehicleProfileBytes) + " bytes: no such profile"});
    } else if (profiles_.count(request.vehicle_profile) == 0) {
      std::string known;
      for (const auto& [name, info] : profiles_) known += (known.empty() ? "" : ", ") + name;
      issues.push_back({"vehicle_profile", "unknown profile '" + request.vehicle_profile + "' (the service has " +
                                               (known.empty() ? std::string("none") : known) + ")"});
    }
  }
  if (request.vehicle) {
    for (const VehicleField& f : kVehicleFields) {
      const double v = (*request.vehicle).*f.member;
      if (!std::isfinite(v) || v < f.min || v > f.max) {
        std::ostringstream problem;
        problem << "must be in [" << f.min << ", " << f.max << "] " << f.unit << ", got " << v;
        issues.push_back({std::string("vehicle.") + f.key, problem.str()});
      }
    }
  }
  return issues;
}

VehicleInfo StartPlanner::vehicle_for(const PullOutRequest& request) const {
  if (request.vehicle) return *request.vehicle;
  if (!request.vehicle_profile.empty()) {
    const auto it = profiles_.find(request.vehicle_profile);
    if (it != profiles_.end()) return it->second;
  }
  return vehicle_;
}

double planning_horizon_m(const StartPlannerParameters& p, const VehicleInfo& vehicle) {
  const TargetFilteringParameters& f = p.path_safety_check.target_filtering;
  // Ahead: a path runs forward_path_length beyond its start, and beyond the freespace end pose;
  // the safety check looks object_check_forward_distance ahead of the vehicle on it.
  const double ahead = p.forward_path_length + std::max(0.0, p.freespace_planner.end_pose_search_end_distance) +
                       f.object_check_forward_distance;
  // Behind: the reverse to a start candidate, the road kept behind it, and the safety check's look back.
  const double behind = p.max_back_distance + kBackwardPathLength + f.object_check_backward_distance;
  // The freespace costmap's square window, to its corner.
  const double window = std::sqrt(2.0) * freespace_window_half_size(p.freespace_planner, vehicle);
  double margin = 0.0;
  for (double m : p.collision_check_margins) margin = std::max(margin, m);
  return std::max({ahead, behind, window, p.surround_moving_obstacle_check.search_radius}) + vehicle.length_m() +
         margin + kHorizonSlack;
}

std::vector<RequestIssue> StartPlanner::validate(const PullOutRequest& request) const {
  auto issues =
      validate_request_structure(request, limits_, available_planners(), map_ != nullptr, grid_only_allowed());
  for (auto& issue : vehicle_issues(request)) issues.push_back(std::move(issue));
  if (!issues.empty() || (request.lanes.empty() && !has_route(request))) return issues;
  const VehicleInfo vehicle = vehicle_for(request);
  const RequestLanes lanes = request_lanes(request, map_.get(), vehicle, parameters_, limits_);
  if (!lanes.issues.empty()) return lanes.issues;
  // No LaneWorld here: its index and outline cost far more than this one question, and
  // validation runs without the request's deadline (VehicleSession::on_request). O(vertices).
  const bool inside = lanes_contain(lanes.lanes, to_vec(request.ego_pose));
  if (auto issue = check_start_on_lanes(lanes.lanes, inside, request.ego_pose, vehicle)) issues.push_back(*issue);
  return issues;
}

std::vector<RequestIssue> StartPlanner::validate(const ExecutionProgress& progress) const {
  return validate_progress(progress, limits_);
}

std::shared_ptr<const PlannedWorld> StartPlanner::planned_world(const PullOutRequest& request,
                                                                std::vector<RequestIssue>& issues) const {
  issues = validate_request_structure(request, limits_, available_planners(), map_ != nullptr, grid_only_allowed());
  for (auto& issue : vehicle_issues(request)) issues.push_back(std::move(issue));
  if (!issues.empty()) return nullptr;
  const VehicleInfo vehicle = vehicle_for(request);
  if (request.lanes.empty() && !has_route(request)) {  // a grid-only request: no lanes (as plan())
    return std::make_shared<const PlannedWorld>(PlannedWorld{{}, request.objects, vehicle, nullptr});
  }
  RequestLanes lanes = request_lanes(request, map_.get(), vehicle, parameters_, limits_);
  if (!lanes.issues.empty()) {
    issues = std::move(lanes.issues);
    return nullptr;
  }
  return std::make_shared<const PlannedWorld>(PlannedWorld{std::move(lanes.lanes), request.objects, vehicle, nullptr});
}

bool StartPlanner::grid_only_allowed() const { return parameters_.freespace_planner.enable_freespace_planner; }

PlanningResult StartPlanner::plan_grid_only(const PullOutRequest& request, const VehicleInfo& vehicle,
                                            const StopCondition& stop) const {
  PlanningResult result;
  const FreespaceParameters& p = parameters_.freespace_planner;
  std::vector<Polygon> obstacles;
  for (const Object& o : request.objects) {
    if (std::abs(o.velocity_mps) >= parameters_.th_moving_object_velocity) continue;
    if (!parameters_.object_types_to_check_for_path_generation.includes(o.object_class)) continue;
    obstacles.push_back(object_polygon(o));
  }
  // The costmap is built within the search's own budget too (a grid of max_grid_cells is the
  // costliest set-up there is).
  const Costmap costmap = freespace_costmap(p, &*request.occupancy_grid, nullptr, obstacles, request.ego_pose, 0.0,
                                            stop.with_budget_ms(p.time_limit));
  FreespaceGoalResult r;
  if (costmap.stopped() != StopReason::kNone) {
    r.stopped = costmap.stopped();
    r.status = r.stopped == StopReason::kCancelled ? HybridAStarResult::Status::kCancelled
                                                   : HybridAStarResult::Status::kTimeout;
  } else {
    r = plan_freespace_to_goal(costmap, vehicle, p, request.ego_pose, request.goal_pose, stop, &plan_rrt_star);
  }
  const double margin = 0.5 * p.vehicle_shape_margin;
  const Failure f =
      r.stopped != StopReason::kNone ? stopped_failure(r.stopped) : Failure{attempt_outcome(r.status), "to the goal"};
  result.evaluation_table.push_back({PlannerType::kFreespace, margin, 0.0, f.outcome, f.detail});
  if (r.status == HybridAStarResult::Status::kSuccess) {
    result.outcome = PlanningResult::Outcome::kFound;
    result.path = std::move(r.path);
    publish_checked(result, static_obstacle_checker(request, vehicle, parameters_), margin, parameters_);
    return result;
  }
  // Only the caller's limits make the planning time out; freespace's own time_limit is in the row.
  if (r.stopped == StopReason::kDeadline || r.stopped == StopReason::kCancelled) result.stopped = r.stopped;
  result.timed_out = result.stopped == StopReason::kDeadline;
  result.outcome = PlanningResult::Outcome::kNoPath;
  result.path = make_stop_path(request);
  result.stop_reason = "freespace to the goal: " + describe(result.evaluation_table.back());
  result.path.reasons.push_back(result.stop_reason);
  return result;
}

PlanningResult StartPlanner::plan(const PullOutRequest& request, const StopCondition& stop,
                                  const PlannedWorld* previous) const {
  const auto t0 = std::chrono::steady_clock::now();
  PlanningResult result;
  const std::vector<Lane>* planned_lanes = nullptr;  // the lanes planned on, once known
  std::shared_ptr<const LaneWorld> lane_world;       // built from them, once complete
  const auto finish = [&](PlanningResult& r) {
    if (r.outcome != PlanningResult::Outcome::kRejected) {
      r.world = std::make_shared<const PlannedWorld>(
          PlannedWorld{planned_lanes != nullptr ? *planned_lanes : std::vector<Lane>{}, request.objects,
                       vehicle_for(request), lane_world});
    }
    r.planning_time_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    r.path.vehicle_id = request.vehicle_id;
    r.path.request_id = request.request_id;
    r.path.stamp_ns = request.stamp_ns;
  };
  // The caller's stop condition ended a build step before any attempt: no path, nothing planned.
  const auto stopped_early = [&](PlanningResult& r, StopReason reason) -> PlanningResult& {
    r.outcome = PlanningResult::Outcome::kNoPath;
    r.stopped = reason;
    r.timed_out = reason == StopReason::kDeadline;
    r.path = make_stop_path(request);
    r.stop_reason =
        std::string(r.timed_out ? "planning deadline exceeded" : "planning cancelled") + " while building the lanes";
    r.path.reasons.push_back(r.stop_reason);
    finish(r);
    return r;
  };

  result.issues =
      validate_request_structure(request, limits_, available_planners(), map_ != nullptr, grid_only_allowed());
  for (auto& issue : vehicle_issues(request)) result.issues.push_back(std::move(issue));
  if (!result.issues.empty()) {
    result.outcome = PlanningResult::Outcome::kRejected;
    finish(result);
    return result;
  }
  // This request's vehicle (its own, a profile's, or the configured one): every footprint, turning
  // radius and horizon below is its.
  const VehicleInfo vehicle = vehicle_for(request);
  if (request.lanes.empty() && !has_route(request)) {  // validation allowed it: a grid and freespace
    result = plan_grid_only(request, vehicle, stop);
    finish(result);
    return result;
  }
  const RequestLanes lanes = request_lanes(request, map_.get(), vehicle, parameters_, limits_);
  if (!lanes.issues.empty()) {
    result.issues = lanes.issues;
    result.outcome = PlanningResult::Outcome::kRejected;
    finish(result);
    return result;
  }
  planned_lanes = &lanes.lanes;
  // The previous world's, when its lanes are these (identical_lanes: the build is a function of
  // the lanes alone, so it would build the same world). A stopped build is never kept.
  std::shared_ptr<const LaneWorld> built =
      previous != nullptr && previous->lane_world && identical_lanes(previous->lanes, lanes.lanes)
          ? previous->lane_world
          : std::make_shared<const LaneWorld>(lanes.lanes, stop);
  const LaneWorld& world = *built;
  if (world.stopped() != StopReason::kNone) return stopped_early(result, world.stopped());
  lane_world = std::move(built);
  if (auto issue =
          check_start_on_lanes(lanes.lanes, world.contains(to_vec(request.ego_pose)), request.ego_pose, vehicle)) {
    result.issues.push_back(*issue);
    result.outcome = PlanningResult::Outcome::kRejected;
    finish(result);
    return result;
  }

  StartPlannerParameters params = parameters_;
  if (!request.overrides.search_priority.empty()) params.search_priority = request.overrides.search_priority;
  if (request.overrides.search_policy) params.search_policy = *request.overrides.search_policy;

  // The road lanes to pull out onto: the map's pick for the route, or the chain through the road
  // lane nearest to the vehicle.
  const bool from_map = !lanes.road_ids.empty();
  LaneChain road_on_map;
  const LaneChain& road = from_map
                              ? (road_on_map = world.chain_of(indices_of(world, lanes.road_ids)))
                              : world.chain_through(*world.nearest_lane(to_vec(request.ego_pose), LaneSubtype::kRoad));

  // Static obstacles: objects slower than th_moving_object_velocity, of the classes to check.
  // All of them are considered, wherever they stand (Autoware keeps only those overlapping the
  // pull-out lanes, which misses a car standing half on the kerb next to the path).
  // Only those that may reach into the planning horizon: no path or check comes near the others.
  const Aabb near_square = horizon_square(request.ego_pose.x, request.ego_pose.y, planning_horizon_m(params, vehicle));
  std::vector<Obstacle> obstacles;
  std::vector<Polygon> obstacle_polygons;
  for (const Object& o : request.objects) {
    if (!object_near(o, near_square)) continue;
    if (std::abs(o.velocity_mps) >= params.th_moving_object_velocity) continue;
    if (!params.object_types_to_check_for_path_generation.includes(o.object_class)) continue;
    obstacles.push_back({o.id, object_polygon(o)});
    obstacle_polygons.push_back(obstacles.back().polygon);
  }
  const ObjectChecker checker(vehicle_footprint(vehicle), std::move(obstacles));
  // The lanes the vehicle stands in: the shoulder chain when it is on a shoulder, else the road.
  LaneChain shoulder;
  const LaneChain* pull_out = &road;
  if (from_map) {
    if (!lanes.pull_out_ids.empty()) {
      shoulder = world.chain_of(indices_of(world, lanes.pull_out_ids));
      pull_out = &shoulder;
    }
  } else {
    for (std::size_t i : world.lanes_containing(to_vec(request.ego_pose))) {
      if (world.lanes()[i].subtype == LaneSubtype::kRoadShoulder) {
        pull_out = &world.chain_through(i);
        break;
      }
    }
  }
  double horizon = 0.0;
  double smallest_margin = std::numeric_limits<double>::infinity();
  for (double m : params.collision_check_margins) {
    horizon = std::max(horizon, m);
    smallest_margin = std::min(smallest_margin, m);
  }
  const PlanningContext context{world,
                                road,
                                *pull_out,
                                checker,
                                vehicle,
                                params,
                                request.goal_pose,
                                horizon,
                                request.ego_pose,
                                request.occupancy_grid ? &*request.occupancy_grid : nullptr,
                                &obstacle_polygons,
                                smallest_margin,
                                params.enable_back ? params.max_back_distance : 0.0,
                                std::abs(params.backward_velocity)};

  std::vector<std::unique_ptr<PullOutPlanner>> planners;
  for (PlannerType t : params.search_priority) {
    if (auto p = make_planner(t, params)) planners.push_back(std::move(p));
  }
  // Start candidates: the current pose, then poses behind it (enable_back).
  const StartCandidateSearch search = search_start_candidates(context, params, request.ego_pose);
  const std::vector<StartCandidate>& starts = search.candidates;
  for (const auto& skipped : search.skipped) {
    result.evaluation_table.push_back(
        {PlannerType::kNone, 0.0, skipped.backward_distance, AttemptOutcome::kStartInvalid, skipped.reason});
  }
  // The order of (candidate, planner) pairs inside one margin, per search_policy.
  std::vector<std::pair<std::size_t, std::size_t>> order;
  if (params.search_policy == SearchPolicy::kPlannerPriority) {
    for (std::size_t p = 0; p < planners.size(); ++p) {
      for (std::size_t c = 0; c < starts.size(); ++c) order.emplace_back(c, p);
    }
  } else {
    for (std::size_t c = 0; c < starts.size(); ++c) {
      for (std::size_t p = 0; p < planners.size(); ++p) order.emplace_back(c, p);
    }
  }

  // Freespace's one time_limit over every start it is tried from, counted from its first attempt.
  std::optional<StopCondition> freespace_until;
  const auto freespace_stop = [&]() -> const StopCondition& {
    if (!freespace_until) freespace_until = stop.with_budget_ms(params.freespace_planner.time_limit);
    return *freespace_until;
  };
  // The chosen candidate as the result, planned from `start` at `margin`: the straight reverse to
  // a start candidate behind the vehicle first, then checked and finished.
  const auto accept = [&](const PathCandidate& chosen, PlannerType type, const StartCandidate& start, double margin) {
    result.outcome = PlanningResult::Outcome::kFound;
    result.path = chosen.build();
    result.path.found = true;
    result.path.planner_type = type;
    // The vehicle moves towards the centerline: right when it starts left of it.
    result.path.turn_signal = result.path.shift_length_m > 0.0   ? TurnSignal::kRight
                              : result.path.shift_length_m < 0.0 ? TurnSignal::kLeft
                                                                 : TurnSignal::kNone;
    if (start.backward_distance > 0.0) {
      // Pair: cruise at backward_velocity, reached over half the segment (a = v^2 / L) so that
      // the vehicle stops at its end.
      const double v = params.backward_velocity;
      result.path.partial_paths.insert(result.path.partial_paths.begin(),
                                       reverse_segment(context, params, request.ego_pose, start));
      result.path.pairs_terminal_velocity_and_accel.insert(result.path.pairs_terminal_velocity_and_accel.begin(),
                                                           {v, -v * v / start.backward_distance});
    }
    publish_checked(result, checker, margin, params);
    finish(result);
  };

  // Each (start, planner) pair is planned once, on first use; the margin ladder only re-reads
  // the candidates' clearances.
  std::vector<std::optional<PlannerCandidates>> planned(starts.size() * planners.size());
  for (double margin : params.collision_check_margins) {
    for (const auto& [ci, pi] : order) {
      result.stopped = stop.check();
      if (result.stopped != StopReason::kNone) break;
      const StartCandidate& start = starts[ci];
      auto& slot = planned[ci * planners.size() + pi];
      if (!slot) {
        const bool freespace = planners[pi]->type() == PlannerType::kFreespace;
        slot = planners[pi]->plan(context, start.pose, freespace ? freespace_stop() : stop);
      }
      // The caller's limits end the whole search; a planner's own budget only its attempt.
      if (slot->stopped == StopReason::kDeadline || slot->stopped == StopReason::kCancelled) {
        result.stopped = slot->stopped;
      }
      const Selection sel = select_candidate(*slot, margin);
      result.evaluation_table.push_back(
          {planners[pi]->type(), margin, start.backward_distance, sel.outcome, sel.detail});
      if (sel.chosen != nullptr) {
        accept(*sel.chosen, planners[pi]->type(), start, margin);
        return result;
      }
      if (result.stopped != StopReason::kNone) break;
    }
    if (result.stopped != StopReason::kNone) break;
  }

  // Nothing found in one move: the planners' multi-move manoeuvres (the geometric planner's
  // shunting) from the vehicle's pose, in search_priority order, at the smallest margin. They
  // reverse on their own (as far as the room behind and max_back_distance allow), so the start
  // candidates behind the vehicle add nothing.
  if (result.stopped == StopReason::kNone) {
    for (const auto& planner : planners) {
      result.stopped = stop.check();
      if (result.stopped != StopReason::kNone) break;
      const PlannerCandidates moves = planner->plan_multi_move(context, request.ego_pose, stop);
      if (moves.stopped == StopReason::kDeadline || moves.stopped == StopReason::kCancelled) {
        result.stopped = moves.stopped;
      }
      if (moves.candidates.empty() && !moves.failure && moves.stopped == StopReason::kNone) continue;  // has none
      const Selection sel = select_candidate(moves, smallest_margin);
      result.evaluation_table.push_back(
          {planner->type(), smallest_margin, 0.0, sel.outcome, sel.chosen != nullptr ? "shunting" : sel.detail});
      if (sel.chosen != nullptr) {
        accept(*sel.chosen, planner->type(), StartCandidate{request.ego_pose, 0.0}, smallest_margin);
        return result;
      }
      if (result.stopped != StopReason::kNone) break;
    }
  }

  // Nothing found: the freespace fallback (unless it was searched in the order already).
  const bool freespace_listed = std::find(params.search_priority.begin(), params.search_priority.end(),
                                          PlannerType::kFreespace) != params.search_priority.end();
  // The current pose first (candidate 0), then the start candidates behind it, nearest first, all
  // within one time_limit: a candidate adds what the current pose cannot reach, end poses ahead of
  // it (those of the current pose blocked) or a start the costmap finds free.
  if (params.freespace_planner.enable_freespace_planner && !freespace_listed && result.stopped == StopReason::kNone) {
    const FreespacePullOut freespace(params.freespace_planner, &plan_rrt_star);
    for (const StartCandidate& start : starts) {
      const PlannerCandidates fallback = freespace.plan(context, start.pose, freespace_stop());
      if (fallback.stopped == StopReason::kDeadline || fallback.stopped == StopReason::kCancelled) {
        result.stopped = fallback.stopped;
      }
      // The costmap keeps the grown footprint off every object: the margin is half the growth.
      const double margin = 0.5 * params.freespace_planner.vehicle_shape_margin;
      const Selection sel = select_candidate(fallback, 1e-6);  // any clearance: no contact
      result.evaluation_table.push_back(
          {PlannerType::kFreespace, margin, start.backward_distance, sel.outcome, sel.detail});
      if (sel.chosen != nullptr) {
        accept(*sel.chosen, PlannerType::kFreespace, start, margin);
        return result;
      }
      if (fallback.stopped != StopReason::kNone) break;  // the budget too: it is spent
    }
  }

  result.outcome = PlanningResult::Outcome::kNoPath;
  result.path = make_stop_path(request);
  result.path.reasons = no_path_reasons(result.evaluation_table);
  result.timed_out = result.stopped == StopReason::kDeadline;
  if (result.stopped != StopReason::kNone) {
    std::ostringstream os;
    os << (result.timed_out ? "planning deadline exceeded" : "planning cancelled") << " after "
       << result.evaluation_table.size() << " attempts";
    result.stop_reason = os.str();
    result.path.reasons.push_back(result.stop_reason);
  } else if (planners.empty()) {
    result.stop_reason = "no planner enabled";
    result.path.reasons.push_back(result.stop_reason);
  } else if (starts.empty()) {
    result.stop_reason = "no start pose candidate: boxed in";
    for (const auto& skipped : search.skipped) {
      result.path.reasons.push_back(skipped.reason + " (" + format_margin(skipped.backward_distance) + " m back)");
    }
  } else {
    result.stop_reason = "no safe path at any collision margin";
  }
  finish(result);
  return result;
}

}  // namespace pullout
