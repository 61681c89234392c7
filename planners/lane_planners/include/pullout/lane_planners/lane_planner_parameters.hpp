// Parameters of the lane-based planners (shift, geometric, clothoid) and of the reference path
// they share. Names follow Autoware's start_planner.param.yaml (flat keys, see config/pullout.yaml);
// StartPlannerParameters (pipeline/parameters.hpp) derives from this struct, so each key stays a
// direct member (`parameters.lateral_jerk`). Validated by validate_parameters().
#pragma once

#include <vector>

namespace pullout {

struct LanePlannerParameters {
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

  // --- geometric pull-out (two arcs joined by a common tangent) ---
  double geometric_pull_out_velocity{1.0};                       // [m/s]
  double arc_path_interval{1.0};                                 // [m] point spacing on the arcs
  double lane_departure_margin{0.2};                             // [m] footprint clearance to the lane edge
  double geometric_pull_out_max_steer_angle_margin_scale{0.72};  // x vehicle max steer
  bool divide_pull_out_path{true};                               // stop between the arcs to re-steer
  double geometric_collision_check_distance_from_end{0.0};       // [m]
  // Shunts (a forward and a reverse full-lock arc) before the S, where no single S gets out; 0: none.
  int geometric_pull_out_max_shunts{10};

  // --- clothoid pull-out (clothoid-arc-clothoid turns) ---
  double clothoid_initial_velocity{1.0};                               // [m/s]
  double clothoid_acceleration{1.0};                                   // [m/s^2]
  std::vector<double> clothoid_max_steer_angles_deg{5.0, 10.0, 20.0};  // tried in order
  double clothoid_max_steer_angle_rate_deg_per_sec{10.0};              // [deg/s]
  double clothoid_collision_check_distance_from_end{0.0};              // [m]
  bool check_clothoid_path_lane_departure{true};
};

}  // namespace pullout
