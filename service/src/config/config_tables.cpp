// The config tables: every key of config/pullout.yaml, once (see config_table.hpp).
//
// Order is file order. Allowed values are what the algorithms need to be well defined (positive
// intervals and limits, at least one sample) plus generous upper bounds where a typo would make a
// search explode in time or memory (a 1 mm centerline interval, a million samples). Checks between
// keys (maximum >= minimum) are validate_parameters() in the core and service_problems() in
// config.cpp. To add a key: add the member (with its default) to the struct and a line here, then
// regenerate config/pullout.yaml with `pullout_service --print-config`.
#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <string_view>

#include <yaml-cpp/yaml.h>

#include "config/config_table.hpp"
#include "pullout/freespace/freespace_search.hpp"

namespace pullout::config_table {
namespace {

using P = StartPlannerParameters;

bool listed(const std::string& key, const std::string_view* begin, const std::string_view* end) {
  return std::find(begin, end, key) != end;
}

// Autoware start_planner parameters that this version does not implement: a clearer message
// than "unknown key" for users who bring Autoware's file along.
const char* start_planner_hint(const std::string& key) {
  static constexpr std::array<std::string_view, 5> kAutowareOnly{
      "th_distance_to_middle_of_the_road", "maximum_longitudinal_deviation", "minimum_shift_length",
      "turn_signal_on_centerline_start", "debug"};
  return listed(key, kAutowareOnly.begin(), kAutowareOnly.end()) ? "Autoware parameter not supported in this version"
                                                                 : nullptr;
}

// Autoware freespace_planner keys this version does not implement (the rrtstar group: RRT* runs
// with its first solution, see freespace_ompl/rrt_star.hpp).
const char* freespace_hint(const std::string& key) {
  static constexpr std::array<std::string_view, 5> kAutowareOnly{
      "rrtstar", "minimum_turning_radius", "maximum_turning_radius", "turning_radius_size", "only_behind_solutions"};
  return listed(key, kAutowareOnly.begin(), kAutowareOnly.end()) ? "Autoware parameter not supported in this version"
                                                                 : nullptr;
}

// Autoware safety-check keys with no meaning here (lanes this version does not model).
const char* safety_hint(const std::string& key) {
  static constexpr std::array<std::string_view, 6> kUnsupported{
      "check_right_side_lane", "check_left_side_lane", "check_other_lane",
      "include_opposite_lane", "invert_opposite_lane", "use_predicted_path_outside_lanelet"};
  return listed(key, kUnsupported.begin(), kUnsupported.end()) ? "Autoware parameter not supported in this version"
                                                               : nullptr;
}

const Table<ObjectTypesToCheck>& object_types_table() {
  using T = ObjectTypesToCheck;
  static const Table<T> t{{
      field("check_car", &T::check_car, "", AnyValue{}, ""),
      field("check_truck", &T::check_truck, "", AnyValue{}, ""),
      field("check_bus", &T::check_bus, "", AnyValue{}, ""),
      field("check_trailer", &T::check_trailer, "", AnyValue{}, ""),
      field("check_bicycle", &T::check_bicycle, "", AnyValue{}, ""),
      field("check_motorcycle", &T::check_motorcycle, "", AnyValue{}, ""),
      field("check_pedestrian", &T::check_pedestrian, "", AnyValue{}, ""),
      field("check_unknown", &T::check_unknown, "", AnyValue{}, ""),
  }};
  return t;
}

const Table<EgoPredictedPathParameters>& ego_predicted_path_table() {
  using T = EgoPredictedPathParameters;
  static const Table<T> t{{
      field("min_velocity", &T::min_velocity, "m/s", in(0.0, 50.0), "lower clamp of the predicted speed"),
      field("min_acceleration", &T::min_acceleration, "m/s^2", in(-10.0, 10.0),
            "lower bound of the predicted acceleration"),
      field("time_horizon_for_front_object", &T::time_horizon_for_front_object, "s", in(0.0, 60.0), ""),
      field("time_horizon_for_rear_object", &T::time_horizon_for_rear_object, "s", in(0.0, 60.0), ""),
      // Time steps are bounded below so that a horizon has at most a few thousand samples.
      field("time_resolution", &T::time_resolution, "s", in(0.01, 10.0), ""),
      field("delay_until_departure", &T::delay_until_departure, "s", in(0.0, 60.0),
            "the ego is predicted to stand this long first"),
  }};
  return t;
}

const Table<TargetFilteringParameters>& object_lane_configuration_table() {
  using T = TargetFilteringParameters;
  static const Table<T> t{
      {
          field("check_current_lane", &T::check_current_lane, "", AnyValue{},
                "objects on the road lanes the path merges into"),
          field("check_shoulder_lane", &T::check_shoulder_lane, "", AnyValue{}, "objects on road shoulders"),
      },
      &safety_hint};
  return t;
}

const Table<TargetFilteringParameters>& target_filtering_table() {
  using T = TargetFilteringParameters;
  static const Table<T> t{{
                              field("safety_check_time_horizon", &T::safety_check_time_horizon, "s", in(0.0, 60.0),
                                    "predicted paths are cut here"),
                              field("safety_check_time_resolution", &T::safety_check_time_resolution, "s",
                                    in(0.01, 10.0), "predicted paths are resampled at this step"),
                              field("object_check_forward_distance", &T::object_check_forward_distance, "m",
                                    in(0.0, 1000.0), "ahead of the ego, along the lane"),
                              field("object_check_backward_distance", &T::object_check_backward_distance, "m",
                                    in(0.0, 1000.0), "behind the ego, along the lane"),
                              field("ignore_object_velocity_threshold", &T::ignore_object_velocity_threshold, "m/s",
                                    at_least(0.0), "slower objects are not safety targets"),
                              group("object_types_to_check", &T::object_types_to_check, &object_types_table, ""),
                              group("object_lane_configuration", &object_lane_configuration_table, ""),
                              field("use_all_predicted_path", &T::use_all_predicted_path, "", AnyValue{},
                                    "false: only the most confident predicted path"),
                              // Autoware's older name of use_all_predicted_path: both must allow all paths.
                              reader<T>("check_all_predicted_path",
                                        [](MapReader& r, T& p) {
                                          bool check_all = true;
                                          if (r.read("check_all_predicted_path", check_all)) {
                                            p.use_all_predicted_path = p.use_all_predicted_path && check_all;
                                          }
                                        }),
                          },
                          &safety_hint};
  return t;
}

const Table<RssParameters>& rss_table() {
  using T = RssParameters;
  static const Table<T> t{{
      field("rear_vehicle_reaction_time", &T::rear_vehicle_reaction_time, "s", in(0.0, 10.0), ""),
      field("rear_vehicle_safety_time_margin", &T::rear_vehicle_safety_time_margin, "s", in(0.0, 10.0), ""),
      field("lateral_distance_max_threshold", &T::lateral_distance_max_threshold, "m", in(0.0, 10.0), ""),
      field("longitudinal_distance_min_threshold", &T::longitudinal_distance_min_threshold, "m", in(0.0, 100.0), ""),
      field("longitudinal_velocity_delta_time", &T::longitudinal_velocity_delta_time, "s", in(0.0, 10.0), ""),
      field("front_vehicle_deceleration", &T::front_vehicle_deceleration, "m/s^2", in(-20.0, -0.01), ""),
      field("rear_vehicle_deceleration", &T::rear_vehicle_deceleration, "m/s^2", in(-20.0, -0.01), ""),
      field("extended_polygon_policy", &T::extended_polygon_policy, "", AnyValue{},
            "along_path or rectangle (both extend a rectangle here)"),
  }};
  return t;
}

const Table<SafetyCheckParams>& safety_check_params_table() {
  using T = SafetyCheckParams;
  static const Table<T> t{{
      field("enable_safety_check", &T::enable_safety_check, "", AnyValue{}, ""),
      field("hysteresis_factor_expand_rate", &T::hysteresis_factor_expand_rate, "", in(1.0, 10.0),
            "margins grow by this factor once unsafe"),
      field("collision_check_yaw_diff_threshold", &T::collision_check_yaw_diff_threshold, "rad", in(0.0, 3.15),
            "objects heading further apart are skipped"),
      ignored<T, bool>("publish_debug_marker"),    // no markers here
      ignored<T, double>("backward_path_length"),  // loaded but unused by Autoware too
      ignored<T, double>("forward_path_length"),
      group("rss_params", &T::rss_params, &rss_table, ""),
  }};
  return t;
}

const Table<PathSafetyCheckParameters>& path_safety_check_table() {
  using T = PathSafetyCheckParameters;
  static const Table<T> t{{
      group("ego_predicted_path", &T::ego_predicted_path, &ego_predicted_path_table, ""),
      group("target_filtering", &T::target_filtering, &target_filtering_table, ""),
      group("safety_check_params", &T::safety_check_params, &safety_check_params_table, ""),
  }};
  return t;
}

const Table<SurroundMovingObstacleCheckParameters>& surround_moving_obstacle_check_table() {
  using T = SurroundMovingObstacleCheckParameters;
  static const Table<T> t{{
      field("search_radius", &T::search_radius, "m", at_least(0.0), ""),
      field("th_moving_obstacle_velocity", &T::th_moving_obstacle_velocity, "m/s", at_least(0.0), ""),
      group("object_types_to_check", &T::object_types_to_check, &object_types_table, ""),
  }};
  return t;
}

const Table<StopConditionParameters>& stop_condition_table() {
  using T = StopConditionParameters;
  static const Table<T> t{{
      field("maximum_deceleration_for_stop", &T::maximum_deceleration_for_stop, "m/s^2", in(0.01, 20.0), ""),
      field("maximum_jerk_for_stop", &T::maximum_jerk_for_stop, "m/s^3", in(0.01, 50.0), ""),
  }};
  return t;
}

const Table<FreespaceParameters::SearchConfigs>& search_configs_table() {
  using T = FreespaceParameters::SearchConfigs;
  static const Table<T> t{{
      field("theta_size", &T::theta_size, "", in(8, 720), "heading bins of the lattice"),
      field("angle_goal_range", &T::angle_goal_range, "deg", in(0.1, 180.0), "goal region: heading"),
      field("lateral_goal_range", &T::lateral_goal_range, "m", in(0.0, 10.0), "goal region: lateral"),
      field("longitudinal_goal_range", &T::longitudinal_goal_range, "m", in(0.0, 20.0), "goal region: longitudinal"),
      field("curve_weight", &T::curve_weight, "", in(0.0, 100.0), "extra cost per metre at full steer"),
      field("reverse_weight", &T::reverse_weight, "", in(0.0, 100.0), "extra cost per metre in reverse"),
      field("direction_change_weight", &T::direction_change_weight, "m", in(0.0, 1000.0),
            "cost of each change of direction"),
  }};
  return t;
}

const Table<FreespaceParameters::CostmapConfigs>& costmap_configs_table() {
  using T = FreespaceParameters::CostmapConfigs;
  static const Table<T> t{{
      field("obstacle_threshold", &T::obstacle_threshold, "", in(1, 100),
            "occupancy values >= this (or -1, unknown) are obstacles"),
      field("resolution", &T::resolution, "m", in(0.02, 2.0), "cells of the costmap built from lanes and objects"),
  }};
  return t;
}

const Table<FreespaceParameters::Astar>& astar_table() {
  using T = FreespaceParameters::Astar;
  static const Table<T> t{
      {
          field("use_back", &T::use_back, "", AnyValue{}, "reverse motion primitives"),
          field("distance_heuristic_weight", &T::distance_heuristic_weight, "", in(0.1, 10.0),
                "> 1 is faster, less optimal"),
          field("expansion_distance", &T::expansion_distance, "m", in(0.05, 10.0), "arc length of a motion primitive"),
          field("narrow_heuristic_penalty", &T::narrow_heuristic_penalty, "", in(0.0, 100.0),
                "(not Autoware) heuristic cost x (1 + this) where too narrow to turn; 0 = off"),
          field("turning_heuristic_weight", &T::turning_heuristic_weight, "", in(0.0, 10.0),
                "(not Autoware) heuristic also charges the turning still ahead, x this; 0 = off"),
          field("min_expansion_distance", &T::min_expansion_distance, "m", in(0.0, 10.0),
                "(not Autoware) stuck search: in tight spots drive until contact, at least this far; 0 = off"),
          field("search_from_goal", &T::search_from_goal, "", AnyValue{},
                "(not Autoware) stuck search: also search from a goal in a tight spot"),
          field("stall_expansions", &T::stall_expansions, "", in(0, 10000000),
                "(not Autoware) expansions without progress near the goal before the stuck-search rescue"),
      },
      &freespace_hint};
  return t;
}

const Table<FreespaceParameters>& freespace_table() {
  using T = FreespaceParameters;
  static const Table<T> t{
      {
          field("enable_freespace_planner", &T::enable_freespace_planner, "", AnyValue{},
                "fallback when the lane-based search finds nothing"),
          field("freespace_planner_algorithm", &T::freespace_planner_algorithm, "",
                Choices{{kAstarAlgorithm, kRrtStarAlgorithm}}, "hybrid A* (astar) or seeded RRT* (rrtstar, OMPL)"),
          field("end_pose_search_start_distance", &T::end_pose_search_start_distance, "m", in(0.0, 500.0),
                "end poses on the road centerline from s(ego) + this"),
          field("end_pose_search_end_distance", &T::end_pose_search_end_distance, "m", in(0.0, 500.0),
                "... to s(ego) + this, >= the start distance"),
          field("end_pose_search_interval", &T::end_pose_search_interval, "m", in(0.1, 100.0),
                "spacing of the end poses"),
          field("velocity", &T::velocity, "m/s", in(0.01, 20.0), "speed on the freespace path"),
          field("vehicle_shape_margin", &T::vehicle_shape_margin, "m", in(0.0, 5.0),
                "added to the vehicle length and width"),
          field("time_limit", &T::time_limit, "ms", in(1.0, 60000.0),
                "search budget; the request deadline may cut it shorter"),
          field("max_turning_ratio", &T::max_turning_ratio, "", in(0.05, 1.0),
                "x vehicle.max_steer_angle for the motion primitives"),
          field("turning_steps", &T::turning_steps, "", in(1, 10), "steering angles per side"),
          field("smooth_path", &T::smooth_path, "", AnyValue{},
                "(not Autoware) smooth each direction segment, cusps kept"),
          group("search_configs", &T::search_configs, &search_configs_table, ""),
          group("costmap_configs", &T::costmap_configs, &costmap_configs_table, ""),
          group("astar", &T::astar, &astar_table, ""),
      },
      &freespace_hint};
  return t;
}

}  // namespace

const Table<VehicleInfo>& vehicle_table() {
  // The keys, units and ranges are the core's (kVehicleFields): a request's own vehicle is checked
  // against the same ones.
  static const Table<VehicleInfo> t = [] {
    Table<VehicleInfo> table;
    for (const VehicleField& f : kVehicleFields) {
      table.entries.push_back(field(f.key, f.member, f.unit, in(f.min, f.max), f.comment));
    }
    return table;
  }();
  return t;
}

const Table<StartPlannerParameters>& start_planner_table() {
  static const Table<P> t{
      {
          note<P>("--- execution: when a segment counts as finished ---"),
          field("th_arrived_distance", &P::th_arrived_distance, "m", above(0.0), "within this distance of its end"),
          field("th_stopped_velocity", &P::th_stopped_velocity, "m/s", above(0.0), "|v| below this counts as stopped"),
          field("th_stopped_time", &P::th_stopped_time, "s", at_least(0.0), "stopped for this long"),

          note<P>("--- search ---", true),
          field("collision_check_margins", &P::collision_check_margins, "m", NumberList{1, 16, in(0.0, 10.0)},
                "clearance to static objects, tried in order, decreasing"),
          note<P>("Planners, in order (upper case as in Autoware, or lower case). FREESPACE here runs the\n"
                  "hybrid A* in that place of the order (from the current pose, over the margin ladder);\n"
                  "freespace_planner.enable_freespace_planner below runs it as the fallback when nothing\n"
                  "else is found."),
          field("search_priority", &P::search_priority, "", PlannerList{}, ""),
          field("search_policy", &P::search_policy, "", AnyValue{}, "or distance_priority"),

          note<P>("--- objects considered by path generation ---", true),
          field("th_moving_object_velocity", &P::th_moving_object_velocity, "m/s", at_least(0.0),
                "objects slower than this are static obstacles"),
          group("object_types_to_check_for_path_generation", &P::object_types_to_check_for_path_generation,
                &object_types_table, ""),

          note<P>("--- reference path ---", true),
          field("center_line_path_interval", &P::center_line_path_interval, "m", in(0.05, 10.0),
                "resampling interval of the road centerline"),
          field("forward_path_length", &P::forward_path_length, "m", in(1.0, 10000.0),
                "path length after the start when the goal is farther"),

          note<P>("--- lane departure ---", true),
          field("check_shift_path_lane_departure", &P::check_shift_path_lane_departure, "", AnyValue{}, ""),
          field("allow_check_shift_path_lane_departure_override", &P::allow_check_shift_path_lane_departure_override,
                "", AnyValue{}, ""),
          field("lane_departure_check_expansion_margin", &P::lane_departure_check_expansion_margin, "m", in(0.0, 5.0),
                "footprint inflation for the check"),

          note<P>("--- shift pull-out ---", true),
          field("shift_collision_check_distance_from_end", &P::shift_collision_check_distance_from_end, "m",
                any_number(), "end of the collision-checked section, rel. to the end pose"),
          field("minimum_shift_pull_out_distance", &P::minimum_shift_pull_out_distance, "m", at_least(0.0), ""),
          field("lateral_jerk", &P::lateral_jerk, "m/s^3", above(0.0), ""),
          field("lateral_acceleration_sampling_num", &P::lateral_acceleration_sampling_num, "", in(1, 100),
                "samples between minimum and maximum_lateral_acc"),
          field("minimum_lateral_acc", &P::minimum_lateral_acc, "m/s^2", above(0.0), ""),
          field("maximum_lateral_acc", &P::maximum_lateral_acc, "m/s^2", above(0.0), ">= minimum_lateral_acc"),
          field("maximum_curvature", &P::maximum_curvature, "1/m", above(0.0), ""),
          field("end_pose_curvature_threshold", &P::end_pose_curvature_threshold, "1/m", above(0.0), ""),
          field("maximum_longitudinal_acc", &P::maximum_longitudinal_acc, "m/s^2", above(0.0),
                "cap of the pull-out acceleration"),

          note<P>("--- backward start-pose search: reverse first when no path starts at the current pose ---", true),
          field("enable_back", &P::enable_back, "", AnyValue{}, ""),
          field("max_back_distance", &P::max_back_distance, "m", in(0.0, 200.0), ""),
          // With max_back_distance this bounds the start candidates to at most 2001.
          field("backward_search_resolution", &P::backward_search_resolution, "m", in(0.1, 100.0),
                "spacing of the start candidates"),
          field("collision_check_margin_from_front_object", &P::collision_check_margin_from_front_object, "m",
                in(0.0, 50.0), "candidates this close to an object ahead are skipped"),
          field("ignore_distance_from_lane_end", &P::ignore_distance_from_lane_end, "m", at_least(0.0),
                "candidates this close to the lane end are skipped"),
          field("backward_velocity", &P::backward_velocity, "m/s", in_closed_open(-10.0, 0.0),
                "speed of the reverse segment"),

          note<P>("--- geometric pull-out: two arcs joined by a common tangent ---", true),
          field("geometric_pull_out_velocity", &P::geometric_pull_out_velocity, "m/s", in(0.01, 20.0), ""),
          field("arc_path_interval", &P::arc_path_interval, "m", in(0.05, 10.0), "point spacing on the arcs"),
          field("lane_departure_margin", &P::lane_departure_margin, "m", in(0.0, 5.0),
                "footprint clearance to the lane edge"),
          field("geometric_pull_out_max_steer_angle_margin_scale", &P::geometric_pull_out_max_steer_angle_margin_scale,
                "", in(0.01, 1.0), "x vehicle.max_steer_angle"),
          field("divide_pull_out_path", &P::divide_pull_out_path, "", AnyValue{}, "stop between the arcs to re-steer"),
          field("geometric_collision_check_distance_from_end", &P::geometric_collision_check_distance_from_end, "m",
                any_number(), ""),
          field("geometric_pull_out_max_shunts", &P::geometric_pull_out_max_shunts, "", in(0, 50),
                "forward and reverse full-lock moves before the S where no S gets out (0: none)"),

          note<P>("--- clothoid pull-out: clothoid-arc-clothoid turns ---", true),
          field("clothoid_initial_velocity", &P::clothoid_initial_velocity, "m/s", in(0.01, 20.0), ""),
          field("clothoid_acceleration", &P::clothoid_acceleration, "m/s^2", in(0.0, 10.0), ""),
          field("clothoid_max_steer_angles_deg", &P::clothoid_max_steer_angles_deg, "deg",
                NumberList{1, 16, in(0.5, 80.0)}, "tried in order"),
          field("clothoid_max_steer_angle_rate_deg_per_sec", &P::clothoid_max_steer_angle_rate_deg_per_sec, "deg/s",
                in(0.1, 1000.0), ""),
          field("clothoid_collision_check_distance_from_end", &P::clothoid_collision_check_distance_from_end, "m",
                any_number(), ""),
          field("check_clothoid_path_lane_departure", &P::check_clothoid_path_lane_departure, "", AnyValue{}, ""),

          note<P>("--- departure: approval, turn signal, re-planning ---", true),
          field("prepare_time_before_start", &P::prepare_time_before_start, "s", in(0.0, 60.0),
                "turn signal on this long (after approval) before departure"),
          field("backward_path_update_duration", &P::backward_path_update_duration, "s", in(0.0, 600.0),
                "a re-sent request re-plans at most this often before departure"),

          note<P>("--- dynamic safety (forward segments only) ---", true),
          field("skip_rear_vehicle_check", &P::skip_rear_vehicle_check, "", AnyValue{},
                "true: check even when the ego blocks the lane for a rear vehicle"),
          field("extra_width_margin_for_rear_obstacle", &P::extra_width_margin_for_rear_obstacle, "m", in(0.0, 10.0),
                "added to the rear vehicle's width for that test"),
          group("stop_condition", &P::stop_condition, &stop_condition_table,
                "the stop inserted when unsafe after departure"),
          group("surround_moving_obstacle_check", &P::surround_moving_obstacle_check,
                &surround_moving_obstacle_check_table, "before departure"),
          group("path_safety_check", &P::path_safety_check, &path_safety_check_table, ""),

          note<P>("--- freespace pull-out: hybrid A* with Reeds-Shepp shots, out of tight spots and parking lots ---\n"
                  "Costmap: the request's occupancy grid, else the lanes (drivable) and static objects rasterised.",
                  true),
          group("freespace_planner", &P::freespace_planner, &freespace_table, ""),
      },
      &start_planner_hint};
  return t;
}

namespace {

const Table<RequestLimits>& limits_table() {
  using T = RequestLimits;
  static const Table<T> t{{
      field("max_lanes", &T::max_lanes, "", at_least(1), ""),
      field("max_points_per_line", &T::max_points_per_line, "", at_least(1), "points in one bound or centerline"),
      field("max_objects", &T::max_objects, "", at_least(1), ""),
      field("max_polygon_points", &T::max_polygon_points, "", at_least(1), "points of one object polygon"),
      field("max_predicted_paths", &T::max_predicted_paths, "", at_least(1), "per object"),
      field("max_predicted_path_points", &T::max_predicted_path_points, "", at_least(1), "per predicted path"),
      field("max_route_lanelets", &T::max_route_lanelets, "", at_least(1), ""),
      field("max_grid_cells", &T::max_grid_cells, "", at_least(1), "occupancy grid width x height"),
      // Ten minutes: anything longer is a typo.
      field("max_deadline_ms", &T::max_deadline_ms, "ms", in_open_closed(0.0, 600000.0),
            "cap of a request's deadline_ms"),
      // Beyond 1e9 m, distances lose centimetres to rounding.
      field("max_coordinate_m", &T::max_coordinate_m, "m", in_open_closed(0.0, 1e9),
            "|x|, |y| of every point and pose, object lengths and widths"),
      field("max_horizon_lane_length_m", &T::max_horizon_lane_length_m, "m", above(0.0),
            "lane bounds kept within the planning horizon, all lanes"),
      // 1,000 m/s: Mach 3; the stop profile and the predictions stay bounded below it.
      field("max_speed_mps", &T::max_speed_mps, "m/s", in_open_closed(0.0, 1000.0),
            "|speed| of the ego, every object and a progress sample"),
  }};
  return t;
}

const Table<ReplicaConfig>& replica_table() {
  using T = ReplicaConfig;
  static const Table<T> t{{
      field("enabled", &T::enabled, "", AnyValue{},
            "serve the fleet with the other replicas on the domain; off: another service is a duplicate"),
      field("lease_duration_ms", &T::lease_duration_ms, "ms", in(100, 60000),
            "DDS participant lease: a killed replica's vehicles are taken over within about this"),
  }};
  return t;
}

const Table<ServiceConfig>& service_table() {
  using T = ServiceConfig;
  static const Table<T> t{{
      field("worker_threads", &T::worker_threads, "", in(1, 64), "planning threads"),
      field("default_deadline_ms", &T::default_deadline_ms, "ms", above(0.0),
            "planning budget when a request gives none, <= limits.max_deadline_ms"),
      field("quick_answer_ms", &T::quick_answer_ms, "ms", in(0.0, 50.0),
            "a search that ends within this is answered without a `planning` status first; 0 = `planning` at once"),
      field("quick_answer_on_dispatcher", &T::quick_answer_on_dispatcher, "", AnyValue{},
            "the quick attempt on the dispatcher thread itself (no hand-off) while it keeps up"),
      field("log_level", &T::log_level, "", Choices{{kLogLevels.begin(), kLogLevels.end()}}, ""),
      field("progress_timeout_s", &T::progress_timeout_s, "s", in(0.0, 60.0),
            "a departed vehicle silent this long is told to stop (odometry lost); 0 = never"),
      field("fleet_clearance_m", &T::fleet_clearance_m, "m", in(0.0, 5.0),
            "vehicles that see each other: margin around the ego when checked against another's path"),
      note<T>("Vehicle sessions. A session is evicted (its path and status instances unregistered on the\n"
              "DDS writers, one log line) when it is idle, that is no search running and not driving a path\n"
              "(departed, not completed), and either its vehicle's request and progress writers are gone or\n"
              "it had no request and no progress for session_idle_timeout_s. A vehicle driving a path is\n"
              "evicted only when its writers are gone and it was silent that long. When max_vehicles are\n"
              "held, a new vehicle evicts the least recently active idle one; when none is idle it is\n"
              "rejected (status rejected, error 'service.max_vehicles: ...'). About 85 KB per session.\n"
              "max_vehicles must not exceed resource_limits.max_instances of the DDS profiles (checked at\n"
              "start-up): each session holds one instance on the path and on the status writer."),
      field("session_idle_timeout_s", &T::session_idle_timeout_s, "s", in(0.0, 86400.0), "0 = never by time"),
      field("max_vehicles", &T::max_vehicles, "", in(1, 1000000), "sessions held at once"),
      field("state_dir", &T::state_dir, "", AnyValue{},
            "every vehicle's request, path and status kept here and read back at start-up (restart without "
            "loss); relative to this file; empty = off"),
      note<T>("Replicas: several services on one domain, each vehicle served by one of them; when it dies\n"
              "another takes its vehicles over (same path, segment and approval). See README, Replicas."),
      group("replica", &T::replica, &replica_table, ""),
      note<T>("Size limits of one request; a larger request is rejected with the field named."),
      group("limits", &T::limits, &limits_table, ""),
  }};
  return t;
}

const Table<DdsConfig>& dds_table() {
  using T = DdsConfig;
  static const Table<T> t{{
      // The highest domain id the RTPS port mapping allows.
      field("domain_id", &T::domain_id, "", in(0, 232), "--domain overrides it"),
      field("profiles_file", &T::profiles_file, "", AnyValue{},
            "Fast DDS XML profiles, relative to this file; empty = the built-in loopback-only profiles "
            "(config/dds/loopback.xml, compiled in); dds/network.xml for real networks"),
      field("participant_profile", &T::participant_profile, "", NonEmpty{}, "a profile of that file"),
      field("security_dir", &T::security_dir, "", AnyValue{},
            "DDS Security credentials (ca.pem, cert.pem, key.pem, governance.p7s, permissions.p7s), relative to "
            "this file; empty = no security. scripts/make-test-pki makes TEST credentials"),
  }};
  return t;
}

const Table<MapConfig>& map_table() {
  using T = MapConfig;
  static const Table<T> t{{
      field("path", &T::path, "", AnyValue{}, "relative to this file; empty = no map (inline lanes only)"),
  }};
  return t;
}

const Table<MetricsConfig>& metrics_table() {
  using T = MetricsConfig;
  static const Table<T> t{{
      field("enabled", &T::enabled, "", AnyValue{}, "serve /metrics, /healthz and /readyz over HTTP"),
      field("address", &T::address, "", NonEmpty{}, "IPv4 address to listen on; 0.0.0.0 = every interface"),
      field("port", &T::port, "", in(1, 65535), "TCP port"),
  }};
  return t;
}

const Table<ObservabilityConfig>& observability_table() {
  using T = ObservabilityConfig;
  static const Table<T> t{{
      note<T>("Prometheus metrics (pullout_* at /metrics) and health endpoints on one HTTP port: /healthz\n"
              "answers 200 while the dispatcher loop is responsive, /readyz once the DDS entities, the config\n"
              "and the planning threads are up. No authentication: keep the address on loopback or a\n"
              "management network."),
      group("metrics", &T::metrics, &metrics_table, ""),
      field("log_format", &T::log_format, "", Choices{{kLogFormats.begin(), kLogFormats.end()}},
            "json: one JSON object per line (time, level, logger, message, fields); --log-format overrides it"),
      field("on_duplicate_service", &T::on_duplicate_service, "",
            Choices{{kDuplicatePolicies.begin(), kDuplicatePolicies.end()}},
            "another pullout_service on the domain: warn (log, metric) or exit (code 4)"),
  }};
  return t;
}

// [m] Rounded to the millimetre, for comments (4.89, not 4.890000000000001).
double to_mm(double v) { return std::round(v * 1000.0) / 1000.0; }

// A profile name: what a request's vehicle_profile must equal.
bool valid_profile_name(const std::string& name) {
  return !name.empty() && name.size() <= 64 && std::all_of(name.begin(), name.end(), [](unsigned char c) {
    return std::isalnum(c) != 0 || c == '_' || c == '-' || c == '.';
  });
}

// `vehicle_profiles`: a mapping of names to vehicles, each read with the vehicle table (a key a
// profile leaves out takes VehicleInfo's default). A file that has the key replaces the default
// profiles whole.
Entry<Config> vehicle_profiles_entry() {
  Entry<Config> e;
  e.key = "vehicle_profiles";
  e.read = [](MapReader& r, Config& c) {
    if (!r.has("vehicle_profiles")) return;
    const YAML::Node node = r.get("vehicle_profiles");
    const std::string path = r.key_path("vehicle_profiles");
    if (node.IsNull()) {
      c.vehicle_profiles.clear();
      return;
    }
    if (!node.IsMap()) {
      r.problems().push_back(path + ": expected a mapping of profile names to vehicles" + yaml_fields::where(node));
      return;
    }
    VehicleProfiles profiles;
    for (const auto& item : node) {
      const std::string name = item.first.IsScalar() ? item.first.Scalar() : std::string();
      if (!valid_profile_name(name)) {
        r.problems().push_back(path + ": profile name '" + name + "' must be 1..64 letters, digits, '_', '-' or '.'" +
                               yaml_fields::where(item.first));
        continue;
      }
      VehicleInfo vehicle;
      MapReader sub(item.second, join_path(path, name), r.problems());
      if (sub.valid()) read_table(vehicle_table(), sub, vehicle);
      profiles[name] = vehicle;
    }
    c.vehicle_profiles = std::move(profiles);
  };
  e.check = [](const Config& c, const std::string& prefix, Problems& out) {
    for (const auto& [name, vehicle] : c.vehicle_profiles) {
      if (!valid_profile_name(name)) {
        out.push_back(join_path(prefix, "vehicle_profiles") + ": profile name '" + name +
                      "' must be 1..64 letters, digits, '_', '-' or '.'");
      }
      check_table(vehicle_table(), vehicle, join_path(join_path(prefix, "vehicle_profiles"), name), out);
    }
  };
  e.write = [](const Config& c, int indent, Doc& out) {
    out.push_back({indent, "vehicle_profiles:", "", false});
    for (const auto& [name, vehicle] : c.vehicle_profiles) {
      out.push_back({indent + 2, name + ":",
                     "vehicle_length " + encode(to_mm(vehicle.length_m())) + " m, vehicle_width " +
                         encode(to_mm(vehicle.width_m())) + " m",
                     false});
      write_table(vehicle_table(), vehicle, indent + 4, out);
    }
  };
  return e;
}

}  // namespace

const Table<Config>& config_file_table() {
  using T = Config;
  static const Table<T> t{{
      note<T>("The vehicle the service plans for (base_link = rear-axle centre).", true),
      group("vehicle", &T::vehicle, &vehicle_table, ""),
      note<T>("Named vehicles a request may ask for (PullOutRequest.vehicle_profile; a scenario's\n"
              "`vehicle: {profile: bus}`), each with the keys of `vehicle` (a key left out takes its default).\n"
              "A request may also carry its own dimensions; without either it gets `vehicle`. A file that\n"
              "has this key replaces these profiles whole.",
              true),
      vehicle_profiles_entry(),
      note<T>("Planner parameters. Names follow Autoware's start_planner.param.yaml where the concept is\n"
              "the same; the defaults are that file's.",
              true),
      group("start_planner", &T::start_planner, &start_planner_table, ""),
      note<T>("The process.", true),
      group("service", &T::service, &service_table, ""),
      note<T>("DDS. QoS and transports live in the XML profiles file; see config/dds/.", true),
      group("dds", &T::dds, &dds_table, ""),
      note<T>("The Lanelet2 map (Autoware's OSM format) that requests naming route_lanelet_ids plan on.\n"
              "Loaded once at start-up; a file that cannot be read or parsed stops the service with one line.",
              true),
      group("map", &T::map, &map_table, ""),
      note<T>("Operating the service: metrics, health, log format, a second service on the domain.", true),
      group("observability", &T::observability, &observability_table, ""),
  }};
  return t;
}

}  // namespace pullout::config_table
