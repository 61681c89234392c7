// Parameters of the dynamic-object safety checks before and after departure. Names and defaults
// follow Autoware's start_planner.param.yaml (path_safety_check.*, surround_moving_obstacle_check.*,
// stop_condition.*); see config/pullout.yaml. Range-checked by the config tables.
#pragma once

#include <cstdint>
#include <string>

#include "pullout/collision/object_types.hpp"
#include "pullout/model/types.hpp"

namespace pullout {

// How the ego is predicted to move along the current segment.
struct EgoPredictedPathParameters {
  double min_velocity{0.0};  // [m/s] lower clamp of the predicted speed
  // [m/s^2] lower bound of the predicted acceleration: the segment's terminal acceleration is used
  // when larger (Autoware overwrites this value every cycle by max(a_t, 0); pullout honours it).
  double min_acceleration{1.0};
  double time_horizon_for_front_object{10.0};  // [s]
  double time_horizon_for_rear_object{10.0};   // [s]
  double time_resolution{0.5};                 // [s]
  double delay_until_departure{1.0};           // [s] the ego stands still this long first
};

// Which objects are safety targets and how their predicted paths are sampled.
struct TargetFilteringParameters {
  double safety_check_time_horizon{10.0};         // [s] predicted paths are cut here
  double safety_check_time_resolution{1.0};       // [s] predicted paths are resampled at this step
  double object_check_forward_distance{10.0};     // [m] ahead of the ego, along the lane
  double object_check_backward_distance{100.0};   // [m] behind the ego, along the lane
  double ignore_object_velocity_threshold{0.25};  // [m/s] slower objects are not targets
  // Unknown objects are not checked (Autoware's default for the safety checks).
  ObjectTypesToCheck object_types_to_check{true, true, true, true, true, true, true, false};
  bool check_current_lane{true};      // objects on the road lanes the path merges into
  bool check_shoulder_lane{true};     // objects on road shoulders
  bool use_all_predicted_path{true};  // false: only the most confident predicted path
};

enum class ExtendedPolygonPolicy : std::uint8_t { kAlongPath = 0, kRectangle = 1 };

// Responsibility-Sensitive-Safety distance:
//   d_rss = v_rear (t_react + t_margin) + v_rear^2 / (2 |b_rear|) - v_front^2 / (2 |b_front|)
// and the minimum d_min = longitudinal_velocity_delta_time * max(v) + longitudinal_distance_min_threshold.
struct RssParameters {
  double rear_vehicle_reaction_time{2.0};           // [s]
  double rear_vehicle_safety_time_margin{1.0};      // [s]
  double lateral_distance_max_threshold{2.0};       // [m]
  double longitudinal_distance_min_threshold{3.0};  // [m]
  double longitudinal_velocity_delta_time{0.8};     // [s]
  double front_vehicle_deceleration{-1.0};          // [m/s^2] < 0
  double rear_vehicle_deceleration{-1.0};           // [m/s^2] < 0
  ExtendedPolygonPolicy extended_polygon_policy{ExtendedPolygonPolicy::kAlongPath};
};

struct SafetyCheckParams {
  bool enable_safety_check{true};
  double hysteresis_factor_expand_rate{1.0};         // >= 1: margins grow by this once unsafe
  double collision_check_yaw_diff_threshold{1.578};  // [rad] objects heading more apart are skipped
  RssParameters rss_params;
};

struct PathSafetyCheckParameters {
  EgoPredictedPathParameters ego_predicted_path;
  TargetFilteringParameters target_filtering;
  SafetyCheckParams safety_check_params;
};

// Before departure: any object this close moving this fast holds the vehicle.
struct SurroundMovingObstacleCheckParameters {
  double search_radius{10.0};               // [m]
  double th_moving_obstacle_velocity{1.0};  // [m/s]
  // Unknown objects are not checked (Autoware's default for the safety checks).
  ObjectTypesToCheck object_types_to_check{true, true, true, true, true, true, true, false};
};

// The stop inserted when the path becomes unsafe after departure.
struct StopConditionParameters {
  double maximum_deceleration_for_stop{1.0};  // [m/s^2] > 0
  double maximum_jerk_for_stop{1.0};          // [m/s^3] > 0
};

// The safety checks' parameters, as StartPlannerParameters holds them (it derives from this).
struct SafetyParameters {
  PathSafetyCheckParameters path_safety_check;
  SurroundMovingObstacleCheckParameters surround_moving_obstacle_check;
  StopConditionParameters stop_condition;
  bool skip_rear_vehicle_check{false};               // true: never bypass the check for a blocked rear vehicle
  double extra_width_margin_for_rear_obstacle{0.5};  // [m] added to the rear vehicle's width
};

}  // namespace pullout
