// Parameters of the start planner. Names follow Autoware's start_planner.param.yaml where the
// concept is the same (see config/pullout.yaml), defaults are the same as that file's. The core
// assumes valid parameters: each key's allowed values are checked by the config tables
// (pullout::check_config, load_config), the checks between keys by validate_parameters().
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "pullout/model/types.hpp"
#include "pullout/pipeline/object_types.hpp"
#include "pullout/safety/safety_parameters.hpp"
#include "pullout/vehicle/vehicle_info.hpp"

namespace pullout {

// The freespace pull-out (hybrid A*), Autoware's `freespace_planner.` parameters. Unlike Autoware,
// every key here is used.
struct FreespaceParameters {
  bool enable_freespace_planner{true};          // fallback when the lane-based search finds nothing
  double end_pose_search_start_distance{20.0};  // [m] end poses on the road centerline from s(ego) + this ...
  double end_pose_search_end_distance{30.0};    // [m] ... to s(ego) + this
  double end_pose_search_interval{2.0};         // [m] spacing of the end poses
  double velocity{1.0};                         // [m/s] speed on the freespace path
  double vehicle_shape_margin{1.0};             // [m] added to the vehicle's length and width (half each side)
  double time_limit{3000.0};                    // [ms] search budget (the request deadline may cut it shorter)
  double max_turning_ratio{0.7};                // x max_steer_angle for the primitives (0, 1]
  int turning_steps{1};                         // steering angles per side
  struct SearchConfigs {
    int theta_size{120};                  // heading bins of the lattice
    double angle_goal_range{6.0};         // [deg] goal region width in heading
    double lateral_goal_range{0.5};       // [m]
    double longitudinal_goal_range{2.0};  // [m]
    double curve_weight{0.5};             // extra cost per metre at full steer
    double reverse_weight{1.0};           // extra cost per metre reversing
    double direction_change_weight{1.5};  // [m] cost of a change of direction
  } search_configs;
  struct CostmapConfigs {
    int obstacle_threshold{30};  // occupancy grid values >= this (or unknown) are obstacles
    double resolution{0.2};      // [m] cells of the costmap built from lanes and objects
  } costmap_configs;
  struct Astar {
    bool use_back{true};                    // reverse primitives
    double distance_heuristic_weight{2.0};  // > 1: faster, less optimal (Autoware default)
    double expansion_distance{0.5};         // [m] arc length of a motion primitive
    // Not in Autoware: the obstacle-aware heuristic charges up to (1 + this) per metre through
    // places narrower than the vehicle needs to turn (see hybrid_astar.hpp); 0 = plain distance.
    double narrow_heuristic_penalty{3.0};
  } astar;
};

struct StartPlannerParameters {
  // --- execution ---
  double th_arrived_distance{1.0};   // [m] segment end reached within this distance
  double th_stopped_velocity{0.01};  // [m/s] |v| below this counts as stopped
  double th_stopped_time{1.0};       // [s] stopped for this long before a segment counts as done

  // --- search ---
  std::vector<double> collision_check_margins{2.0, 1.0, 0.5, 0.1};                         // [m] tried in order
  std::vector<PlannerType> search_priority{PlannerType::kShift, PlannerType::kGeometric};  // in order
  SearchPolicy search_policy{SearchPolicy::kPlannerPriority};

  // --- objects considered by path generation ---
  double th_moving_object_velocity{1.0};  // [m/s] objects slower than this are static obstacles
  ObjectTypesToCheck object_types_to_check_for_path_generation;

  // --- reference path ---
  double center_line_path_interval{1.0};  // [m] resampling interval of the road centerline
  double forward_path_length{300.0};      // [m] path length after the start when the goal is farther

  // --- lane departure ---
  bool check_shift_path_lane_departure{true};
  bool allow_check_shift_path_lane_departure_override{false};
  double lane_departure_check_expansion_margin{0.0};  // [m] footprint inflation

  // --- shift pull-out ---
  double shift_collision_check_distance_from_end{-10.0};  // [m] collision section end rel. to end pose
  double minimum_shift_pull_out_distance{0.0};            // [m]
  double lateral_jerk{0.5};                               // [m/s^3]
  int lateral_acceleration_sampling_num{3};               // >= 1
  double minimum_lateral_acc{0.15};                       // [m/s^2]
  double maximum_lateral_acc{0.5};                        // [m/s^2]
  double maximum_curvature{0.07};                         // [1/m]
  double end_pose_curvature_threshold{0.1};               // [1/m]
  double maximum_longitudinal_acc{1.0};                   // [m/s^2] cap of the pull-out acceleration

  // --- backward start-pose search ---
  bool enable_back{true};
  double max_back_distance{20.0};                        // [m]
  double backward_search_resolution{2.0};                // [m] spacing of start candidates
  double collision_check_margin_from_front_object{5.0};  // [m] candidates this close to an object ahead are skipped
  double ignore_distance_from_lane_end{0.0};             // [m] candidates this close to the lane end are skipped
  double backward_velocity{-1.0};                        // [m/s] < 0, speed of the reverse segment

  // --- geometric pull-out (two arcs joined by a common tangent) ---
  double geometric_pull_out_velocity{1.0};                       // [m/s]
  double arc_path_interval{1.0};                                 // [m] point spacing on the arcs
  double lane_departure_margin{0.2};                             // [m] footprint clearance to the lane edge
  double geometric_pull_out_max_steer_angle_margin_scale{0.72};  // x vehicle max steer
  bool divide_pull_out_path{true};                               // stop between the arcs to re-steer
  double geometric_collision_check_distance_from_end{0.0};       // [m]

  // --- clothoid pull-out (clothoid-arc-clothoid turns) ---
  double clothoid_initial_velocity{1.0};                               // [m/s]
  double clothoid_acceleration{1.0};                                   // [m/s^2]
  std::vector<double> clothoid_max_steer_angles_deg{5.0, 10.0, 20.0};  // tried in order
  double clothoid_max_steer_angle_rate_deg_per_sec{10.0};              // [deg/s]
  double clothoid_collision_check_distance_from_end{0.0};              // [m]
  bool check_clothoid_path_lane_departure{true};
  // --- dynamic safety, approval, re-planning (see safety/safety_parameters.hpp) ---
  PathSafetyCheckParameters path_safety_check;
  SurroundMovingObstacleCheckParameters surround_moving_obstacle_check;
  StopConditionParameters stop_condition;
  bool skip_rear_vehicle_check{false};               // true: never bypass the check for a blocked rear vehicle
  double extra_width_margin_for_rear_obstacle{0.5};  // [m] added to the rear vehicle's width
  double prepare_time_before_start{0.0};             // [s] turn signal on this long before departure
  double backward_path_update_duration{3.0};         // [s] a re-sent request re-plans at most this often

  // --- freespace pull-out ---
  FreespaceParameters freespace_planner;
};

// Whether this version of the core implements a planner (search_priority may only name these).
bool planner_available(PlannerType type);

// One problem with a parameter: the parameter's name and what is wrong.
struct ParameterIssue {
  std::string name;
  std::string problem;
};

// The checks that involve more than one parameter (maximum >= minimum) and search_priority
// entries this version does not implement; names are config key paths. Empty when valid.
std::vector<ParameterIssue> validate_parameters(const StartPlannerParameters& p);

// Limits on the size of a request, so that one vehicle cannot make the service allocate or compute
// without bound. Defaults are generous for real use.
struct RequestLimits {
  std::size_t max_lanes{256};
  std::size_t max_points_per_line{10000};  // points in one bound or centerline
  std::size_t max_objects{512};
  std::size_t max_polygon_points{64};          // points of one object polygon
  std::size_t max_predicted_paths{16};         // per object
  std::size_t max_predicted_path_points{200};  // per predicted path
  std::size_t max_route_lanelets{1000};
  std::size_t max_grid_cells{std::size_t{16} * 1024 * 1024};
  double max_deadline_ms{10000.0};
};

}  // namespace pullout
