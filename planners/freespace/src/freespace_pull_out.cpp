#include "pullout/freespace/freespace_pull_out.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "pullout/freespace/grid_collision_checker.hpp"
#include "pullout/freespace/path_smoother.hpp"
#include "pullout/geometry/angle.hpp"
#include "pullout/geometry/polyline.hpp"

namespace pullout {

namespace {

constexpr double kTrimDistance = 1.0;  // [m] Autoware's trim around the end pose
constexpr double kWindowExtra = 10.0;  // [m] costmap window beyond the farthest end pose
constexpr int kRoomBisections = 12;    // a shape margin of up to a few metres to about 1 mm
constexpr double kRoomSlack = 0.01;    // [m] left between the start and what its margin reaches

// The pair of a partial path that stops at its end: v reached at half of it (a = v^2 / L).
TerminalVelocityAccel stopping_pair(double v, double length) {
  return {v, length > 1e-9 ? v * std::abs(v) / length : 0.0};
}

// The path smoothed within `stop` when the parameters ask for it (path_smoother.hpp).
void smooth_if_asked(const FreespaceParameters& p, const GridCollisionChecker& checker, const HybridAStarConfig& search,
                     std::vector<Waypoint>& waypoints, const StopCondition& stop) {
  if (!p.smooth_path) return;
  PathSmootherConfig config;
  config.max_curvature = 1.0 / search.turning_radius;
  waypoints = smooth_path(waypoints, checker, config, stop).waypoints;
}

// Andrew's monotone chain: the convex hull of `points`, counter-clockwise.
Polygon convex_hull(std::vector<Vec2> points) {
  std::sort(points.begin(), points.end(),
            [](const Vec2& a, const Vec2& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); });
  if (points.size() < 3) return points;
  const auto cross = [](const Vec2& o, const Vec2& a, const Vec2& b) {
    return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
  };
  Polygon hull(2 * points.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], points[i]) <= 0.0) --k;
    hull[k++] = points[i];
  }
  for (std::size_t i = points.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && cross(hull[k - 2], hull[k - 1], points[i]) <= 0.0) --k;
    hull[k++] = points[i];
  }
  hull.resize(k - 1);
  return hull;
}

}  // namespace

std::vector<Polygon> grown_obstacles(const std::vector<Polygon>& obstacles, double d) {
  std::vector<Polygon> out;
  out.reserve(obstacles.size());
  for (const Polygon& o : obstacles) {
    std::vector<Vec2> moved;
    moved.reserve(4 * o.size());
    for (const Vec2& v : o) {
      for (const Vec2& m : {Vec2(d, d), Vec2(d, -d), Vec2(-d, d), Vec2(-d, -d)}) moved.push_back(v + m);
    }
    out.push_back(convex_hull(std::move(moved)));
  }
  return out;
}

FreespaceSearch freespace_search(const FreespaceParameters& p, const FreespaceSearch& rrt_star) {
  if (p.freespace_planner_algorithm == kRrtStarAlgorithm) {
    if (!rrt_star) throw std::invalid_argument("freespace_planner_algorithm rrtstar: no RRT* search given");
    return rrt_star;
  }
  if (p.freespace_planner_algorithm != kAstarAlgorithm) {
    throw std::invalid_argument("freespace_planner_algorithm: unknown '" + p.freespace_planner_algorithm + "'");
  }
  return [](const GridCollisionChecker& checker, const HybridAStarConfig& config, const Pose2& start, const Pose2& goal,
            const StopCondition& stop) { return HybridAStar(checker, config).plan(start, goal, stop); };
}

FreespacePullOut::FreespacePullOut(const FreespaceParameters& parameters, FreespaceSearch rrt_star)
    : parameters_(parameters), rrt_star_(std::move(rrt_star)) {
  freespace_search(parameters_, rrt_star_);  // the algorithm's name and its search, checked once
}

AttemptOutcome attempt_outcome(HybridAStarResult::Status status) {
  switch (status) {
    case HybridAStarResult::Status::kSuccess:
      return AttemptOutcome::kSuccess;
    case HybridAStarResult::Status::kStartOccupied:
      return AttemptOutcome::kStartInvalid;
    case HybridAStarResult::Status::kGoalOccupied:
      return AttemptOutcome::kGoalInvalid;
    case HybridAStarResult::Status::kTimeout:
      return AttemptOutcome::kTimeout;
    case HybridAStarResult::Status::kCancelled:
      return AttemptOutcome::kCancelled;
    case HybridAStarResult::Status::kNodeLimit:
      return AttemptOutcome::kNodeLimit;
    case HybridAStarResult::Status::kNoPath:
      return AttemptOutcome::kNoPath;
  }
  return AttemptOutcome::kNoPath;
}

HybridAStarConfig freespace_search_config(const VehicleInfo& vehicle, const FreespaceParameters& p) {
  HybridAStarConfig c;
  c.turning_radius = vehicle.wheel_base_m / std::tan(vehicle.max_steer_angle_rad * p.max_turning_ratio);
  c.turning_steps = p.turning_steps;
  c.theta_size = p.search_configs.theta_size;
  c.primitive_length = p.astar.expansion_distance;
  c.use_back = p.astar.use_back;
  c.curve_weight = p.search_configs.curve_weight;
  c.reverse_weight = p.search_configs.reverse_weight;
  c.direction_change_weight = p.search_configs.direction_change_weight;
  c.distance_heuristic_weight = p.astar.distance_heuristic_weight;
  c.narrow_heuristic_penalty = p.astar.narrow_heuristic_penalty;
  c.turning_heuristic_weight = p.astar.turning_heuristic_weight;
  c.min_primitive_length = p.astar.min_expansion_distance;
  c.search_from_goal = p.astar.search_from_goal;
  c.stall_expansions = static_cast<std::size_t>(p.astar.stall_expansions);
  c.longitudinal_goal_range = p.search_configs.longitudinal_goal_range;
  c.lateral_goal_range = p.search_configs.lateral_goal_range;
  c.angle_goal_range = p.search_configs.angle_goal_range * kDegToRad;
  return c;
}

double freespace_window_half_size(const FreespaceParameters& p, const VehicleInfo& vehicle) {
  return p.end_pose_search_end_distance + vehicle.length_m() + kWindowExtra;
}

Footprint freespace_footprint(const VehicleInfo& vehicle, const FreespaceParameters& p) {
  return vehicle_footprint(vehicle, 0.5 * p.vehicle_shape_margin);
}

Footprint freespace_footprint(const VehicleInfo& vehicle, const FreespaceParameters& p, const Costmap& costmap,
                              const Pose2& start) {
  const Footprint plain = vehicle_footprint(vehicle);
  const double half = 0.5 * p.vehicle_shape_margin;
  // The room [m] of one side at the start, up to `cap`: the largest growth of that side alone
  // with which the start is still free (bisection on the exact checker), less kRoomSlack.
  const auto room = [&](double Footprint::*side, double cap) {
    const auto free_with = [&](double e) {
      Footprint f = plain;
      f.*side += e;
      return !GridCollisionChecker(costmap, f).collides(start);
    };
    if (free_with(cap + kRoomSlack)) return cap;
    if (!free_with(0.0)) return 0.0;
    double lo = 0.0;
    double hi = cap + kRoomSlack;
    for (int i = 0; i < kRoomBisections; ++i) {
      const double mid = 0.5 * (lo + hi);
      (free_with(mid) ? lo : hi) = mid;
    }
    return std::max(0.0, lo - kRoomSlack);
  };
  // A full-lock forward turn away from a side swings the rear corner on that side outwards by
  // hypot(R + w, rear) - (R + w) (R the search's turning radius): the side's margin leaves room
  // for that swing, and the rear's margin is kept small enough that its corners' swing fits.
  const double r = freespace_search_config(vehicle, p).turning_radius;
  const auto swing = [r](double across, double rear) { return std::hypot(r + across, rear) - (r + across); };
  const double swing_cap = half + 1.0;  // beyond any swing at a turning radius of a few metres
  // The search covers the motion between its poses with the footprint grown by up to a quarter
  // of a cell (hybrid_astar.hpp): the swing leaves that much too.
  const double sweep = 0.25 * costmap.resolution();
  const double side_room = std::min(room(&Footprint::left, swing_cap), room(&Footprint::right, swing_cap)) - sweep;
  const double half_width = std::min(plain.left, plain.right);
  Footprint out = plain;
  out.front += room(&Footprint::front, half);
  double rear = room(&Footprint::rear, half);
  // Largest rear growth whose corner's swing fits the narrower side's room.
  const double u = r + half_width;
  if (swing(half_width, plain.rear + rear) > side_room) {
    const double fit = std::sqrt(std::max(0.0, (u + side_room) * (u + side_room) - u * u));
    rear = std::clamp(fit - plain.rear, 0.0, rear);
  }
  out.rear += rear;
  const double lateral_swing = swing(half_width, out.rear);
  for (double Footprint::*side : {&Footprint::left, &Footprint::right}) {
    out.*side += std::clamp(room(side, swing_cap) - sweep - lateral_swing, 0.0, half);
  }
  return out;
}

Costmap freespace_costmap(const FreespaceParameters& p, const OccupancyGrid* grid, const LaneWorld* world,
                          const std::vector<Polygon>& obstacles, const Pose2& centre, double half_window,
                          const StopCondition& stop) {
  if (grid != nullptr) {
    Costmap map = Costmap::from_occupancy_grid(*grid, p.costmap_configs.obstacle_threshold, stop);
    if (!obstacles.empty() && map.stopped() == StopReason::kNone) map.add_obstacles(obstacles, stop);
    return map;
  }
  Aabb lanes_box;
  std::vector<Polygon> drivable;
  for (const LaneGeometry& lane : world->lanes()) {
    drivable.push_back(lane.polygon);
    lanes_box.extend(lane.box.min);
    lanes_box.extend(lane.box.max);
  }
  Aabb extent;
  extent.min = lanes_box.min.cwiseMax(Vec2{centre.x - half_window, centre.y - half_window});
  extent.max = lanes_box.max.cwiseMin(Vec2{centre.x + half_window, centre.y + half_window});
  extent = extent.inflated(p.costmap_configs.resolution);  // a blocked rim around the lanes
  return Costmap::from_polygons(extent, p.costmap_configs.resolution, drivable, world->outer_edges(), obstacles, stop);
}

SplitPath split_at_cusps(const std::vector<Waypoint>& w, double velocity) {
  SplitPath out;
  std::size_t first = 0;
  for (std::size_t i = 1; i < w.size(); ++i) {
    // Waypoint i ends a partial path when the motion after it goes the other way (or it is last).
    const bool last = i + 1 == w.size();
    if (!last && w[i + 1].direction == w[i].direction) continue;
    PathWithLaneId part;
    const int dir = w[i].direction;
    for (std::size_t k = first; k <= i; ++k) {
      PathPoint pt;
      pt.pose = w[k].pose;
      pt.longitudinal_velocity_mps = k == i ? 0.0 : dir * velocity;
      part.points.push_back(std::move(pt));
    }
    out.pairs.push_back(stopping_pair(dir * velocity, polyline_length(part)));
    out.partial_paths.push_back(std::move(part));
    out.directions.push_back(dir);
    first = i;
  }
  return out;
}

FreespaceGoalResult plan_freespace_to_goal(const Costmap& costmap, const VehicleInfo& vehicle,
                                           const FreespaceParameters& p, const Pose2& start, const Pose2& goal,
                                           const StopCondition& stop, const FreespaceSearch& rrt_star) {
  FreespaceGoalResult out;
  // The margin where the start allows it, as from a lane (see the header): the full margin put a
  // car parked in a bay of a grid in collision at Autoware's default of 1.0 m.
  const GridCollisionChecker checker(costmap, freespace_footprint(vehicle, p, costmap, start));
  HybridAStarConfig config = freespace_search_config(vehicle, p);
  const HybridAStarResult r =
      freespace_search(p, rrt_star)(checker, config, start, goal, stop.with_budget_ms(p.time_limit));
  out.status = r.status;
  out.stopped = r.stopped;
  out.expansions = r.expansions;
  if (r.status != HybridAStarResult::Status::kSuccess) return out;
  std::vector<Waypoint> waypoints = r.waypoints;
  smooth_if_asked(p, checker, config, waypoints, stop);
  SplitPath split = split_at_cusps(waypoints, p.velocity);
  out.path.partial_paths = std::move(split.partial_paths);
  out.path.pairs_terminal_velocity_and_accel = std::move(split.pairs);
  out.path.start_pose = start;
  out.path.end_pose = r.waypoints.back().pose;
  out.path.found = true;
  out.path.planner_type = PlannerType::kFreespace;
  return out;
}

PlannerCandidates FreespacePullOut::plan(const PlanningContext& ctx, const Pose2& start,
                                         const StopCondition& stop) const {
  PlannerCandidates out;
  const FreespaceParameters& p = parameters_;
  // One budget (time_limit) for every end pose; the caller's deadline and cancellation stay in.
  const StopCondition until = stop.with_budget_ms(p.time_limit);
  out.stopped = until.check();
  if (out.stopped != StopReason::kNone) return out;  // before the costmap, the heaviest set-up
  const std::vector<Polygon> no_obstacles;
  const std::vector<Polygon>& obstacles = ctx.obstacle_polygons != nullptr ? *ctx.obstacle_polygons : no_obstacles;
  const double half_window = freespace_window_half_size(p, ctx.vehicle);
  // The costmap and the search are shared by every end pose; heavy, so built once, within `until`.
  // RRT* gets the objects grown by kRrtStarObjectClearance where the start allows (see the header).
  const bool grow = p.freespace_planner_algorithm == kRrtStarAlgorithm && !obstacles.empty();
  Costmap costmap = freespace_costmap(p, ctx.occupancy_grid, &ctx.world,
                                      grow ? grown_obstacles(obstacles, kRrtStarObjectClearance) : obstacles, ctx.ego,
                                      half_window, until);
  out.stopped = costmap.stopped();
  if (out.stopped != StopReason::kNone) return out;
  if (grow && GridCollisionChecker(costmap, freespace_footprint(ctx.vehicle, p, costmap, start)).collides(start)) {
    costmap = freespace_costmap(p, ctx.occupancy_grid, &ctx.world, obstacles, ctx.ego, half_window, until);
    out.stopped = costmap.stopped();
    if (out.stopped != StopReason::kNone) return out;
  }
  const GridCollisionChecker checker(costmap, freespace_footprint(ctx.vehicle, p, costmap, start));
  const HybridAStarConfig search_config = freespace_search_config(ctx.vehicle, p);
  const FreespaceSearch search = freespace_search(p, rrt_star_);

  // The end poses lie ahead of the start (the current pose or a start candidate behind it), as
  // the lane planners' do.
  const Polyline& center = ctx.road.centerline;
  const double s_start = center.project(to_vec(start)).s;
  Failure last_failure{AttemptOutcome::kGoalInvalid, "no end pose on the road ahead"};
  for (double d = p.end_pose_search_start_distance; d <= p.end_pose_search_end_distance + 1e-9;
       d += p.end_pose_search_interval) {
    const double s_end = s_start + d;
    if (s_end > center.length()) break;
    out.stopped = until.check();
    if (out.stopped != StopReason::kNone) break;
    const Pose2 end_pose = center.pose_at(s_end);
    HybridAStarResult r = search(checker, search_config, start, end_pose, until);
    if (r.stopped != StopReason::kNone) {
      out.stopped = r.stopped;
      break;
    }
    if (r.status != HybridAStarResult::Status::kSuccess) {
      last_failure = Failure{attempt_outcome(r.status),
                             std::string("end pose ") + format_fixed(d, 1) + " m ahead: " + to_string(r.status)};
      if (r.status == HybridAStarResult::Status::kStartOccupied) break;  // the same for every end pose
      continue;
    }
    smooth_if_asked(p, checker, search_config, r.waypoints, until);
    PathCandidate candidate;
    std::vector<Pose2> poses;
    for (const Waypoint& w : r.waypoints) poses.push_back(w.pose);
    const auto clearance = section_clearance(ctx, poses, 0, poses.size() - 1);
    candidate.clearance = clearance.distance;
    candidate.nearest_obstacle = clearance.obstacle_id;
    const PlanningContext* c = &ctx;
    candidate.build = [c, fp = p, waypoints = std::move(r.waypoints), exact = r.reached_exact_goal, end_pose, s_end,
                       s_start]() {
      SplitPath split = split_at_cusps(waypoints, fp.velocity);
      const std::int64_t fallback_id = road_lane_id_at(*c, s_start);
      PathWithLaneId& last = split.partial_paths.back();
      // Road points follow from one interval after tail_from.
      double tail_from = s_end;
      if (split.directions.back() > 0) {
        // Continue the last forward partial path on the centerline (trimmed when the search
        // stopped in the goal region rather than on the end pose).
        if (!exact) {
          auto& pts = last.points;
          for (std::size_t i = 1; i < pts.size(); ++i) {
            if (std::hypot(pts[i].pose.x - end_pose.x, pts[i].pose.y - end_pose.y) < kTrimDistance) {
              pts.erase(pts.begin() + static_cast<std::ptrdiff_t>(i), pts.end());
              break;
            }
          }
          tail_from = s_end + kTrimDistance - c->parameters.center_line_path_interval;
        }
        last.points.back().longitudinal_velocity_mps = fp.velocity;
      } else {
        // Arrived in reverse: the road part is a partial path of its own, from the end pose.
        PathWithLaneId road;
        PathPoint first;
        first.pose = last.points.back().pose;
        first.longitudinal_velocity_mps = fp.velocity;
        road.points.push_back(first);
        split.partial_paths.push_back(std::move(road));
        split.pairs.push_back({});
        split.directions.push_back(1);
      }
      PathWithLaneId& forward = split.partial_paths.back();
      const RoadEnd end = find_path_end(*c, s_end);
      std::vector<PathPoint> tail = centerline_points(*c, tail_from, end);
      for (auto& pt : tail) forward.points.push_back(std::move(pt));
      if (forward.points.size() < 2) forward.points.push_back(forward.points.back());
      // The last partial path accelerates to the freespace velocity over its freespace part.
      const double len = std::max(1e-3, polyline_length(forward));
      split.pairs.back() = {fp.velocity, fp.velocity * fp.velocity / (2.0 * len)};
      PullOutPath path;
      for (auto& part : split.partial_paths) {
        for (auto& pt : part.points) pt.lane_ids = lane_ids_at(*c, to_vec(pt.pose), fallback_id);
      }
      path.partial_paths = std::move(split.partial_paths);
      path.pairs_terminal_velocity_and_accel = std::move(split.pairs);
      path.start_pose = waypoints.front().pose;
      path.end_pose = end_pose;
      path.shift_length_m = c->road.centerline.project(to_vec(waypoints.front().pose)).lateral;
      return path;
    };
    out.candidates.push_back(std::move(candidate));
    return out;
  }
  if (out.stopped == StopReason::kNone) out.failure = last_failure;
  return out;
}

}  // namespace pullout
