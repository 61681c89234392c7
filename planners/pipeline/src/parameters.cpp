// Range checks of the planner and vehicle parameters (see parameters.hpp).
//
// The bounds are what the algorithms need to be well defined (positive intervals and limits, at
// least one sample) plus generous upper bounds where a typo would make the search explode in time
// or memory (a 1 mm centerline interval, a million acceleration samples).
#include "pullout/pipeline/parameters.hpp"

#include <cmath>
#include <sstream>
#include <string>

#include "pullout/model/names.hpp"

namespace pullout {
namespace {

bool is_search_planner(PlannerType p) {
  return p == PlannerType::kShift || p == PlannerType::kGeometric || p == PlannerType::kClothoid ||
         p == PlannerType::kFreespace;
}

// "shift, geometric": the planners this version implements (planner_available), for messages.
std::string available_planner_names() {
  std::string names;
  for (const PlannerType p :
       {PlannerType::kShift, PlannerType::kGeometric, PlannerType::kClothoid, PlannerType::kFreespace}) {
    if (!planner_available(p)) continue;
    if (!names.empty()) names += ", ";
    names += to_string(p);
  }
  return names;
}

std::string text(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

class Checker {
 public:
  explicit Checker(std::vector<ParameterIssue>& issues) : issues_(issues) {}

  void fail(const std::string& name, const std::string& problem) { issues_.push_back({name, problem}); }

  // Each returns false (after recording the issue) when the value is out of range.
  bool finite(const std::string& name, double v) {
    if (std::isfinite(v)) return true;
    fail(name, "must be a finite number, got " + text(v));
    return false;
  }
  void positive(const std::string& name, double v) {
    if (finite(name, v) && !(v > 0.0)) fail(name, "must be > 0, got " + text(v));
  }
  void non_negative(const std::string& name, double v) {
    if (finite(name, v) && v < 0.0) fail(name, "must be >= 0, got " + text(v));
  }
  void in_range(const std::string& name, double v, double lo, double hi) {
    if (finite(name, v) && (v < lo || v > hi)) {
      fail(name, "must be in [" + text(lo) + ", " + text(hi) + "], got " + text(v));
    }
  }

 private:
  std::vector<ParameterIssue>& issues_;
};

}  // namespace

std::vector<ParameterIssue> validate_parameters(const StartPlannerParameters& p) {
  std::vector<ParameterIssue> issues;
  Checker c(issues);

  c.positive("th_arrived_distance", p.th_arrived_distance);
  c.positive("th_stopped_velocity", p.th_stopped_velocity);
  c.non_negative("th_stopped_time", p.th_stopped_time);

  constexpr std::size_t kMaxMargins = 16;
  if (p.collision_check_margins.empty()) {
    c.fail("collision_check_margins", "must list at least one margin");
  } else if (p.collision_check_margins.size() > kMaxMargins) {
    c.fail("collision_check_margins", "at most " + std::to_string(kMaxMargins) + " margins, got " +
                                          std::to_string(p.collision_check_margins.size()));
  }
  for (std::size_t i = 0; i < p.collision_check_margins.size(); ++i) {
    c.in_range("collision_check_margins[" + std::to_string(i) + "]", p.collision_check_margins[i], 0.0, 10.0);
  }

  if (p.search_priority.empty()) c.fail("search_priority", "must list at least one planner");
  for (std::size_t i = 0; i < p.search_priority.size(); ++i) {
    const std::string name = "search_priority[" + std::to_string(i) + "]";
    const PlannerType planner = p.search_priority[i];
    if (!is_search_planner(planner)) {
      c.fail(name, std::string("'") + to_string(planner) + "' is not a planner that can be searched");
    } else if (!planner_available(planner)) {
      c.fail(name, std::string("planner '") + to_string(planner) +
                       "' is not available in this version (available: " + available_planner_names() + ")");
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (p.search_priority[j] == planner) {
        c.fail(name, std::string("planner '") + to_string(planner) + "' is listed twice");
        break;
      }
    }
  }
  if (p.search_policy != SearchPolicy::kPlannerPriority && p.search_policy != SearchPolicy::kDistancePriority) {
    c.fail("search_policy", "must be planner_priority or distance_priority");
  }

  c.non_negative("th_moving_object_velocity", p.th_moving_object_velocity);

  c.in_range("center_line_path_interval", p.center_line_path_interval, 0.05, 10.0);
  c.in_range("forward_path_length", p.forward_path_length, 1.0, 10000.0);

  c.in_range("lane_departure_check_expansion_margin", p.lane_departure_check_expansion_margin, 0.0, 5.0);

  c.finite("shift_collision_check_distance_from_end", p.shift_collision_check_distance_from_end);
  c.non_negative("minimum_shift_pull_out_distance", p.minimum_shift_pull_out_distance);
  c.positive("lateral_jerk", p.lateral_jerk);
  constexpr int kMaxAccelerationSamples = 100;
  if (p.lateral_acceleration_sampling_num < 1 || p.lateral_acceleration_sampling_num > kMaxAccelerationSamples) {
    c.fail("lateral_acceleration_sampling_num", "must be in [1, " + std::to_string(kMaxAccelerationSamples) +
                                                    "], got " + std::to_string(p.lateral_acceleration_sampling_num));
  }
  c.positive("minimum_lateral_acc", p.minimum_lateral_acc);
  c.positive("maximum_lateral_acc", p.maximum_lateral_acc);
  if (std::isfinite(p.minimum_lateral_acc) && std::isfinite(p.maximum_lateral_acc) &&
      p.minimum_lateral_acc > p.maximum_lateral_acc) {
    c.fail("maximum_lateral_acc",
           "must be >= minimum_lateral_acc (" + text(p.minimum_lateral_acc) + "), got " + text(p.maximum_lateral_acc));
  }
  c.positive("maximum_curvature", p.maximum_curvature);
  c.positive("end_pose_curvature_threshold", p.end_pose_curvature_threshold);
  c.positive("maximum_longitudinal_acc", p.maximum_longitudinal_acc);

  c.in_range("max_back_distance", p.max_back_distance, 0.0, 200.0);
  // With the limits above this bounds the start candidates to at most 2001.
  c.in_range("backward_search_resolution", p.backward_search_resolution, 0.1, 100.0);
  c.in_range("collision_check_margin_from_front_object", p.collision_check_margin_from_front_object, 0.0, 50.0);
  c.non_negative("ignore_distance_from_lane_end", p.ignore_distance_from_lane_end);
  if (c.finite("backward_velocity", p.backward_velocity) &&
      !(p.backward_velocity < 0.0 && p.backward_velocity >= -10.0)) {
    c.fail("backward_velocity", "must be in [-10, 0) (reversing), got " + text(p.backward_velocity));
  }

  c.in_range("geometric_pull_out_velocity", p.geometric_pull_out_velocity, 0.01, 20.0);
  c.in_range("arc_path_interval", p.arc_path_interval, 0.05, 10.0);
  c.in_range("lane_departure_margin", p.lane_departure_margin, 0.0, 5.0);
  c.in_range("geometric_pull_out_max_steer_angle_margin_scale", p.geometric_pull_out_max_steer_angle_margin_scale, 0.01,
             1.0);
  c.finite("geometric_collision_check_distance_from_end", p.geometric_collision_check_distance_from_end);

  c.in_range("clothoid_initial_velocity", p.clothoid_initial_velocity, 0.01, 20.0);
  c.in_range("clothoid_acceleration", p.clothoid_acceleration, 0.0, 10.0);
  if (p.clothoid_max_steer_angles_deg.empty() || p.clothoid_max_steer_angles_deg.size() > 16) {
    c.fail("clothoid_max_steer_angles_deg", "must list 1 to 16 angles");
  }
  for (std::size_t i = 0; i < p.clothoid_max_steer_angles_deg.size(); ++i) {
    c.in_range("clothoid_max_steer_angles_deg[" + std::to_string(i) + "]", p.clothoid_max_steer_angles_deg[i], 0.5,
               80.0);
  }
  c.in_range("clothoid_max_steer_angle_rate_deg_per_sec", p.clothoid_max_steer_angle_rate_deg_per_sec, 0.1, 1000.0);
  c.finite("clothoid_collision_check_distance_from_end", p.clothoid_collision_check_distance_from_end);

  // Dynamic safety. Time steps are bounded below so that a horizon has at most a few thousand samples.
  const std::string ego = "path_safety_check.ego_predicted_path.";
  const EgoPredictedPathParameters& e = p.path_safety_check.ego_predicted_path;
  c.in_range(ego + "min_velocity", e.min_velocity, 0.0, 50.0);
  c.in_range(ego + "min_acceleration", e.min_acceleration, -10.0, 10.0);
  c.in_range(ego + "time_horizon_for_front_object", e.time_horizon_for_front_object, 0.0, 60.0);
  c.in_range(ego + "time_horizon_for_rear_object", e.time_horizon_for_rear_object, 0.0, 60.0);
  c.in_range(ego + "time_resolution", e.time_resolution, 0.01, 10.0);
  c.in_range(ego + "delay_until_departure", e.delay_until_departure, 0.0, 60.0);
  const std::string tf = "path_safety_check.target_filtering.";
  const TargetFilteringParameters& f = p.path_safety_check.target_filtering;
  c.in_range(tf + "safety_check_time_horizon", f.safety_check_time_horizon, 0.0, 60.0);
  c.in_range(tf + "safety_check_time_resolution", f.safety_check_time_resolution, 0.01, 10.0);
  c.in_range(tf + "object_check_forward_distance", f.object_check_forward_distance, 0.0, 1000.0);
  c.in_range(tf + "object_check_backward_distance", f.object_check_backward_distance, 0.0, 1000.0);
  c.non_negative(tf + "ignore_object_velocity_threshold", f.ignore_object_velocity_threshold);
  const std::string sc = "path_safety_check.safety_check_params.";
  const SafetyCheckParams& s = p.path_safety_check.safety_check_params;
  c.in_range(sc + "hysteresis_factor_expand_rate", s.hysteresis_factor_expand_rate, 1.0, 10.0);
  c.in_range(sc + "collision_check_yaw_diff_threshold", s.collision_check_yaw_diff_threshold, 0.0, 3.15);
  const std::string rss = sc + "rss_params.";
  c.in_range(rss + "rear_vehicle_reaction_time", s.rss_params.rear_vehicle_reaction_time, 0.0, 10.0);
  c.in_range(rss + "rear_vehicle_safety_time_margin", s.rss_params.rear_vehicle_safety_time_margin, 0.0, 10.0);
  c.in_range(rss + "lateral_distance_max_threshold", s.rss_params.lateral_distance_max_threshold, 0.0, 10.0);
  c.in_range(rss + "longitudinal_distance_min_threshold", s.rss_params.longitudinal_distance_min_threshold, 0.0, 100.0);
  c.in_range(rss + "longitudinal_velocity_delta_time", s.rss_params.longitudinal_velocity_delta_time, 0.0, 10.0);
  c.in_range(rss + "front_vehicle_deceleration", s.rss_params.front_vehicle_deceleration, -20.0, -0.01);
  c.in_range(rss + "rear_vehicle_deceleration", s.rss_params.rear_vehicle_deceleration, -20.0, -0.01);
  c.non_negative("surround_moving_obstacle_check.search_radius", p.surround_moving_obstacle_check.search_radius);
  c.non_negative("surround_moving_obstacle_check.th_moving_obstacle_velocity",
                 p.surround_moving_obstacle_check.th_moving_obstacle_velocity);
  c.in_range("stop_condition.maximum_deceleration_for_stop", p.stop_condition.maximum_deceleration_for_stop, 0.01,
             20.0);
  c.in_range("stop_condition.maximum_jerk_for_stop", p.stop_condition.maximum_jerk_for_stop, 0.01, 50.0);
  c.in_range("extra_width_margin_for_rear_obstacle", p.extra_width_margin_for_rear_obstacle, 0.0, 10.0);
  c.in_range("prepare_time_before_start", p.prepare_time_before_start, 0.0, 60.0);
  c.in_range("backward_path_update_duration", p.backward_path_update_duration, 0.0, 600.0);
  {  // freespace_planner.*
    const FreespaceParameters& f = p.freespace_planner;
    const std::string fp = "freespace_planner.";
    c.in_range(fp + "end_pose_search_start_distance", f.end_pose_search_start_distance, 0.0, 500.0);
    c.in_range(fp + "end_pose_search_end_distance", f.end_pose_search_end_distance, 0.0, 500.0);
    if (std::isfinite(f.end_pose_search_start_distance) && std::isfinite(f.end_pose_search_end_distance) &&
        f.end_pose_search_end_distance < f.end_pose_search_start_distance) {
      c.fail(fp + "end_pose_search_end_distance", "must be >= end_pose_search_start_distance (" +
                                                      text(f.end_pose_search_start_distance) + "), got " +
                                                      text(f.end_pose_search_end_distance));
    }
    c.in_range(fp + "end_pose_search_interval", f.end_pose_search_interval, 0.1, 100.0);
    c.in_range(fp + "velocity", f.velocity, 0.01, 20.0);
    c.in_range(fp + "vehicle_shape_margin", f.vehicle_shape_margin, 0.0, 5.0);
    c.in_range(fp + "time_limit", f.time_limit, 1.0, 60000.0);
    c.in_range(fp + "max_turning_ratio", f.max_turning_ratio, 0.05, 1.0);
    if (f.turning_steps < 1 || f.turning_steps > 10) {
      c.fail(fp + "turning_steps", "must be in [1, 10], got " + std::to_string(f.turning_steps));
    }
    const std::string sc = fp + "search_configs.";
    if (f.search_configs.theta_size < 8 || f.search_configs.theta_size > 720) {
      c.fail(sc + "theta_size", "must be in [8, 720], got " + std::to_string(f.search_configs.theta_size));
    }
    c.in_range(sc + "angle_goal_range", f.search_configs.angle_goal_range, 0.1, 180.0);
    c.in_range(sc + "lateral_goal_range", f.search_configs.lateral_goal_range, 0.0, 10.0);
    c.in_range(sc + "longitudinal_goal_range", f.search_configs.longitudinal_goal_range, 0.0, 20.0);
    c.in_range(sc + "curve_weight", f.search_configs.curve_weight, 0.0, 100.0);
    c.in_range(sc + "reverse_weight", f.search_configs.reverse_weight, 0.0, 100.0);
    c.in_range(sc + "direction_change_weight", f.search_configs.direction_change_weight, 0.0, 1000.0);
    const std::string cc = fp + "costmap_configs.";
    if (f.costmap_configs.obstacle_threshold < 1 || f.costmap_configs.obstacle_threshold > 100) {
      c.fail(cc + "obstacle_threshold",
             "must be in [1, 100], got " + std::to_string(f.costmap_configs.obstacle_threshold));
    }
    c.in_range(cc + "resolution", f.costmap_configs.resolution, 0.02, 2.0);
    c.in_range(fp + "astar.distance_heuristic_weight", f.astar.distance_heuristic_weight, 0.1, 10.0);
    c.in_range(fp + "astar.expansion_distance", f.astar.expansion_distance, 0.05, 10.0);
    c.in_range(fp + "astar.narrow_heuristic_penalty", f.astar.narrow_heuristic_penalty, 0.0, 100.0);
  }
  return issues;
}

std::vector<ParameterIssue> validate_vehicle(const VehicleInfo& v) {
  std::vector<ParameterIssue> issues;
  Checker c(issues);
  c.in_range("wheel_base", v.wheel_base_m, 0.1, 20.0);
  c.in_range("wheel_tread", v.wheel_tread_m, 0.1, 5.0);
  c.in_range("front_overhang", v.front_overhang_m, 0.0, 10.0);
  c.in_range("rear_overhang", v.rear_overhang_m, 0.0, 10.0);
  c.in_range("left_overhang", v.left_overhang_m, 0.0, 2.0);
  c.in_range("right_overhang", v.right_overhang_m, 0.0, 2.0);
  // Below pi/2 so that the minimum turning radius (wheel_base / tan) is positive and finite.
  c.in_range("max_steer_angle", v.max_steer_angle_rad, 0.01, 1.5);
  return issues;
}

}  // namespace pullout
