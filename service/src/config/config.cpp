// Loading and validation of config/pullout.yaml (see config.hpp).
#include "pullout/config/config.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string_view>
#include <utility>

#include <yaml-cpp/yaml.h>

#include "config/config_detail.hpp"
#include "config/yaml_fields.hpp"
#include "pullout/model/names.hpp"

namespace pullout {
namespace {

using yaml_fields::MapReader;
using yaml_fields::Problems;

std::string join_lines(const std::string& file, const std::vector<std::string>& problems) {
  std::string out;
  for (const auto& p : problems) {
    if (!out.empty()) out += '\n';
    out.append(file).append(": ").append(p);
  }
  return out;
}

// Autoware start_planner parameters that this version does not implement: a clearer message
// than "unknown key" for users who bring Autoware's file along.
const char* start_planner_hint(const std::string& key) {
  static constexpr std::array<std::string_view, 5> kAutowareOnly{
      "th_distance_to_middle_of_the_road",
      "maximum_longitudinal_deviation",
      "minimum_shift_length",
      "turn_signal_on_centerline_start",
      "debug",
  };
  if (std::find(kAutowareOnly.begin(), kAutowareOnly.end(), key) != kAutowareOnly.end()) {
    return "Autoware parameter not supported in this version";
  }
  return nullptr;
}

// Autoware freespace_planner keys this version does not implement (the A* is the only algorithm).
const char* freespace_hint(const std::string& key) {
  static constexpr std::array<std::string_view, 6> kAutowareOnly{
      "freespace_planner_algorithm", "rrtstar",
      "minimum_turning_radius",      "maximum_turning_radius",
      "turning_radius_size",         "only_behind_solutions"};
  if (std::find(kAutowareOnly.begin(), kAutowareOnly.end(), key) != kAutowareOnly.end()) {
    return "Autoware parameter not supported in this version (hybrid A* only)";
  }
  return nullptr;
}

void read_freespace(MapReader& parent, FreespaceParameters& out) {
  MapReader r(parent.get("freespace_planner"), parent.key_path("freespace_planner"), parent.problems());
  if (!r.valid()) return;
  r.read("enable_freespace_planner", out.enable_freespace_planner);
  r.read("end_pose_search_start_distance", out.end_pose_search_start_distance);
  r.read("end_pose_search_end_distance", out.end_pose_search_end_distance);
  r.read("end_pose_search_interval", out.end_pose_search_interval);
  r.read("velocity", out.velocity);
  r.read("vehicle_shape_margin", out.vehicle_shape_margin);
  r.read("time_limit", out.time_limit);
  r.read("max_turning_ratio", out.max_turning_ratio);
  r.read("turning_steps", out.turning_steps);
  {
    MapReader sc(r.get("search_configs"), r.key_path("search_configs"), r.problems());
    if (sc.valid()) {
      sc.read("theta_size", out.search_configs.theta_size);
      sc.read("angle_goal_range", out.search_configs.angle_goal_range);
      sc.read("lateral_goal_range", out.search_configs.lateral_goal_range);
      sc.read("longitudinal_goal_range", out.search_configs.longitudinal_goal_range);
      sc.read("curve_weight", out.search_configs.curve_weight);
      sc.read("reverse_weight", out.search_configs.reverse_weight);
      sc.read("direction_change_weight", out.search_configs.direction_change_weight);
      sc.finish();
    }
  }
  {
    MapReader cc(r.get("costmap_configs"), r.key_path("costmap_configs"), r.problems());
    if (cc.valid()) {
      cc.read("obstacle_threshold", out.costmap_configs.obstacle_threshold);
      cc.read("resolution", out.costmap_configs.resolution);
      cc.finish();
    }
  }
  {
    MapReader a(r.get("astar"), r.key_path("astar"), r.problems());
    if (a.valid()) {
      a.read("use_back", out.astar.use_back);
      a.read("distance_heuristic_weight", out.astar.distance_heuristic_weight);
      a.read("expansion_distance", out.astar.expansion_distance);
      a.read("narrow_heuristic_penalty", out.astar.narrow_heuristic_penalty);
      a.finish(&freespace_hint);
    }
  }
  r.finish(&freespace_hint);
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

// A list of numbers; `what` says what they are in the message ("margins [m]").
void read_number_list(MapReader& r, const std::string& key, const char* what, std::vector<double>& out) {
  const YAML::Node n = r.get(key);
  if (!n.IsDefined()) return;
  const std::string path = r.key_path(key);
  if (!n.IsSequence()) {
    r.problems().push_back(path + ": expected a list of " + what + yaml_fields::where(n));
    return;
  }
  std::vector<double> values;
  bool ok = true;
  for (std::size_t i = 0; i < n.size(); ++i) {
    const auto v = yaml_fields::to_double(n[i], yaml_fields::indexed(path, i), r.problems());
    ok = ok && v.has_value();
    if (v) values.push_back(*v);
  }
  if (ok) out = std::move(values);
}

void read_search_priority(MapReader& r, std::vector<PlannerType>& out) {
  const YAML::Node n = r.get("search_priority");
  if (!n.IsDefined()) return;
  const std::string path = r.key_path("search_priority");
  if (!n.IsSequence()) {
    r.problems().push_back(path + ": expected a list of planner names, e.g. [\"SHIFT\"]" + yaml_fields::where(n));
    return;
  }
  std::vector<PlannerType> planners;
  bool ok = true;
  for (std::size_t i = 0; i < n.size(); ++i) {
    const std::string item_path = yaml_fields::indexed(path, i);
    const auto name = yaml_fields::to_string(n[i], item_path, r.problems());
    if (!name) {
      ok = false;
      continue;
    }
    const auto planner = parse_planner_name(*name);
    if (!planner) {
      r.problems().push_back(item_path + ": unknown planner '" + *name +
                             "' (expected SHIFT, GEOMETRIC, CLOTHOID or FREESPACE)" + yaml_fields::where(n[i]));
      ok = false;
      continue;
    }
    planners.push_back(*planner);
  }
  if (ok) out = std::move(planners);
}

void read_search_policy(MapReader& r, SearchPolicy& out) {
  std::string name;
  if (!r.read("search_policy", name)) return;
  if (const auto policy = search_policy_from_string(name)) {
    out = *policy;
  } else {
    r.problems().push_back(r.key_path("search_policy") + ": unknown policy '" + name +
                           "' (expected planner_priority or distance_priority)" +
                           yaml_fields::where(r.get("search_policy")));
  }
}

template <typename Types>
void read_object_types(MapReader& parent, const std::string& key, Types& out) {
  MapReader r(parent.get(key), parent.key_path(key), parent.problems());
  if (!r.valid()) return;
  r.read("check_car", out.check_car);
  r.read("check_truck", out.check_truck);
  r.read("check_bus", out.check_bus);
  r.read("check_trailer", out.check_trailer);
  r.read("check_bicycle", out.check_bicycle);
  r.read("check_motorcycle", out.check_motorcycle);
  r.read("check_pedestrian", out.check_pedestrian);
  r.read("check_unknown", out.check_unknown);
  r.finish();
}

// Autoware safety-check keys that are accepted but have no effect here (debug output, or lanes
// this version does not model).
const char* safety_hint(const std::string& key) {
  static constexpr std::array<std::string_view, 6> kIgnored{
      "check_right_side_lane", "check_left_side_lane", "check_other_lane",
      "include_opposite_lane", "invert_opposite_lane", "use_predicted_path_outside_lanelet",
  };
  if (std::find(kIgnored.begin(), kIgnored.end(), key) != kIgnored.end()) {
    return "Autoware parameter not supported in this version";
  }
  return nullptr;
}

void read_path_safety_check(MapReader& parent, PathSafetyCheckParameters& out) {
  MapReader r(parent.get("path_safety_check"), parent.key_path("path_safety_check"), parent.problems());
  if (!r.valid()) return;
  {
    MapReader e(r.get("ego_predicted_path"), r.key_path("ego_predicted_path"), r.problems());
    if (e.valid()) {
      EgoPredictedPathParameters& p = out.ego_predicted_path;
      e.read("min_velocity", p.min_velocity);
      e.read("min_acceleration", p.min_acceleration);
      e.read("time_horizon_for_front_object", p.time_horizon_for_front_object);
      e.read("time_horizon_for_rear_object", p.time_horizon_for_rear_object);
      e.read("time_resolution", p.time_resolution);
      e.read("delay_until_departure", p.delay_until_departure);
      e.finish();
    }
  }
  {
    MapReader t(r.get("target_filtering"), r.key_path("target_filtering"), r.problems());
    if (t.valid()) {
      TargetFilteringParameters& p = out.target_filtering;
      t.read("safety_check_time_horizon", p.safety_check_time_horizon);
      t.read("safety_check_time_resolution", p.safety_check_time_resolution);
      t.read("object_check_forward_distance", p.object_check_forward_distance);
      t.read("object_check_backward_distance", p.object_check_backward_distance);
      t.read("ignore_object_velocity_threshold", p.ignore_object_velocity_threshold);
      read_object_types(t, "object_types_to_check", p.object_types_to_check);
      MapReader lanes(t.get("object_lane_configuration"), t.key_path("object_lane_configuration"), t.problems());
      if (lanes.valid()) {
        lanes.read("check_current_lane", p.check_current_lane);
        lanes.read("check_shoulder_lane", p.check_shoulder_lane);
        lanes.finish(&safety_hint);
      }
      t.read("use_all_predicted_path", p.use_all_predicted_path);
      bool check_all = true;  // Autoware's older name of use_all_predicted_path
      if (t.read("check_all_predicted_path", check_all))
        p.use_all_predicted_path = p.use_all_predicted_path && check_all;
      t.finish(&safety_hint);
    }
  }
  {
    MapReader s(r.get("safety_check_params"), r.key_path("safety_check_params"), r.problems());
    if (s.valid()) {
      SafetyCheckParams& p = out.safety_check_params;
      s.read("enable_safety_check", p.enable_safety_check);
      s.read("hysteresis_factor_expand_rate", p.hysteresis_factor_expand_rate);
      s.read("collision_check_yaw_diff_threshold", p.collision_check_yaw_diff_threshold);
      bool ignored_flag = false;
      double ignored_length = 0.0;
      s.read("publish_debug_marker", ignored_flag);    // no markers here
      s.read("backward_path_length", ignored_length);  // loaded but unused by Autoware too
      s.read("forward_path_length", ignored_length);
      MapReader rss(s.get("rss_params"), s.key_path("rss_params"), s.problems());
      if (rss.valid()) {
        RssParameters& q = p.rss_params;
        rss.read("rear_vehicle_reaction_time", q.rear_vehicle_reaction_time);
        rss.read("rear_vehicle_safety_time_margin", q.rear_vehicle_safety_time_margin);
        rss.read("lateral_distance_max_threshold", q.lateral_distance_max_threshold);
        rss.read("longitudinal_distance_min_threshold", q.longitudinal_distance_min_threshold);
        rss.read("longitudinal_velocity_delta_time", q.longitudinal_velocity_delta_time);
        rss.read("front_vehicle_deceleration", q.front_vehicle_deceleration);
        rss.read("rear_vehicle_deceleration", q.rear_vehicle_deceleration);
        std::string policy;
        if (rss.read("extended_polygon_policy", policy)) {
          if (policy == "along_path") {
            q.extended_polygon_policy = ExtendedPolygonPolicy::kAlongPath;
          } else if (policy == "rectangle") {
            q.extended_polygon_policy = ExtendedPolygonPolicy::kRectangle;
          } else {
            rss.problems().push_back(rss.key_path("extended_polygon_policy") +
                                     ": expected along_path or rectangle, got '" + policy + "'");
          }
        }
        rss.finish();
      }
      s.finish();
    }
  }
  r.finish();
}

void read_safety_sections(MapReader& r, StartPlannerParameters& p) {
  read_path_safety_check(r, p.path_safety_check);
  {
    MapReader s(r.get("surround_moving_obstacle_check"), r.key_path("surround_moving_obstacle_check"), r.problems());
    if (s.valid()) {
      s.read("search_radius", p.surround_moving_obstacle_check.search_radius);
      s.read("th_moving_obstacle_velocity", p.surround_moving_obstacle_check.th_moving_obstacle_velocity);
      read_object_types(s, "object_types_to_check", p.surround_moving_obstacle_check.object_types_to_check);
      s.finish();
    }
  }
  {
    MapReader s(r.get("stop_condition"), r.key_path("stop_condition"), r.problems());
    if (s.valid()) {
      s.read("maximum_deceleration_for_stop", p.stop_condition.maximum_deceleration_for_stop);
      s.read("maximum_jerk_for_stop", p.stop_condition.maximum_jerk_for_stop);
      s.finish();
    }
  }
  r.read("skip_rear_vehicle_check", p.skip_rear_vehicle_check);
  r.read("extra_width_margin_for_rear_obstacle", p.extra_width_margin_for_rear_obstacle);
  r.read("prepare_time_before_start", p.prepare_time_before_start);
  r.read("backward_path_update_duration", p.backward_path_update_duration);
}

void apply_limits(MapReader& parent, RequestLimits& out) {
  MapReader r(parent.get("limits"), parent.key_path("limits"), parent.problems());
  if (!r.valid()) return;
  r.read("max_lanes", out.max_lanes);
  r.read("max_points_per_line", out.max_points_per_line);
  r.read("max_objects", out.max_objects);
  r.read("max_polygon_points", out.max_polygon_points);
  r.read("max_predicted_paths", out.max_predicted_paths);
  r.read("max_predicted_path_points", out.max_predicted_path_points);
  r.read("max_route_lanelets", out.max_route_lanelets);
  r.read("max_grid_cells", out.max_grid_cells);
  r.read("max_deadline_ms", out.max_deadline_ms);
  r.finish();
}

void apply_service(const YAML::Node& node, ServiceConfig& out, Problems& problems) {
  MapReader r(node, "service", problems);
  if (!r.valid()) return;
  r.read("worker_threads", out.worker_threads);
  r.read("default_deadline_ms", out.default_deadline_ms);
  apply_limits(r, out.limits);
  r.read("log_level", out.log_level);
  r.finish();
}

void apply_dds(const YAML::Node& node, DdsConfig& out, Problems& problems) {
  MapReader r(node, "dds", problems);
  if (!r.valid()) return;
  r.read("domain_id", out.domain_id);
  r.read("profiles_file", out.profiles_file);
  r.read("participant_profile", out.participant_profile);
  r.finish();
}

void apply_map(const YAML::Node& node, MapConfig& out, Problems& problems) {
  MapReader r(node, "map", problems);
  if (!r.valid()) return;
  r.read("path", out.path);
  r.finish();
}

void validate_map(MapConfig& m, const std::filesystem::path& config_dir, Problems& problems) {
  if (m.path.empty()) return;
  std::filesystem::path file(m.path);
  if (file.is_relative()) file = config_dir / file;
  file = file.lexically_normal();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) {
    problems.push_back("map.path: file not found: " + file.string());
    return;
  }
  m.path = file.string();
}

void validate_service(const ServiceConfig& s, Problems& problems) {
  constexpr int kMaxWorkers = 64;
  if (s.worker_threads < 1 || s.worker_threads > kMaxWorkers) {
    problems.push_back("service.worker_threads: must be in [1, " + std::to_string(kMaxWorkers) + "], got " +
                       std::to_string(s.worker_threads));
  }
  const RequestLimits& l = s.limits;
  constexpr double kMaxDeadlineCapMs = 600000.0;  // ten minutes: anything longer is a typo
  if (!(l.max_deadline_ms > 0.0) || l.max_deadline_ms > kMaxDeadlineCapMs) {
    problems.push_back("service.limits.max_deadline_ms: must be in (0, " + format_number(kMaxDeadlineCapMs) +
                       "], got " + format_number(l.max_deadline_ms));
  }
  if (!(s.default_deadline_ms > 0.0) || s.default_deadline_ms > l.max_deadline_ms) {
    problems.push_back("service.default_deadline_ms: must be in (0, service.limits.max_deadline_ms = " +
                       format_number(l.max_deadline_ms) + "], got " + format_number(s.default_deadline_ms));
  }
  const std::array<std::pair<const char*, std::size_t>, 8> sizes{{
      {"max_lanes", l.max_lanes},
      {"max_points_per_line", l.max_points_per_line},
      {"max_objects", l.max_objects},
      {"max_polygon_points", l.max_polygon_points},
      {"max_predicted_paths", l.max_predicted_paths},
      {"max_predicted_path_points", l.max_predicted_path_points},
      {"max_route_lanelets", l.max_route_lanelets},
      {"max_grid_cells", l.max_grid_cells},
  }};
  for (const auto& [name, value] : sizes) {
    if (value < 1) problems.push_back(std::string("service.limits.") + name + ": must be >= 1, got 0");
  }
  if (!is_log_level(s.log_level)) {
    problems.push_back("service.log_level: unknown level '" + s.log_level +
                       "' (expected trace, debug, info, warn, error, critical or off)");
  }
}

void validate_dds(DdsConfig& d, const std::filesystem::path& config_dir, Problems& problems) {
  constexpr int kMaxDomainId = 232;  // the highest domain id the RTPS port mapping allows
  if (d.domain_id < 0 || d.domain_id > kMaxDomainId) {
    problems.push_back("dds.domain_id: must be in [0, " + std::to_string(kMaxDomainId) + "], got " +
                       std::to_string(d.domain_id));
  }
  if (d.participant_profile.empty()) problems.push_back("dds.participant_profile: must not be empty");
  if (d.profiles_file.empty()) {
    problems.push_back("dds.profiles_file: required (a Fast DDS XML profiles file, e.g. dds/loopback.xml)");
    return;
  }
  std::filesystem::path file(d.profiles_file);
  if (file.is_relative()) file = config_dir / file;
  file = file.lexically_normal();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) {
    problems.push_back("dds.profiles_file: file not found: " + file.string());
    return;
  }
  d.profiles_file = file.string();
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// shared with scenario.cpp (config_detail.hpp)

std::optional<PlannerType> parse_planner_name(const std::string& name) {
  // Autoware writes planner names in upper case ("SHIFT"), the model's names are lower case.
  return planner_type_from_string(lower(name));
}

bool is_log_level(const std::string& level) {
  static constexpr std::array<std::string_view, 7> kLevels{"trace", "debug",    "info", "warn",
                                                           "error", "critical", "off"};
  return std::find(kLevels.begin(), kLevels.end(), level) != kLevels.end();
}

std::string format_number(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

YAML::Node load_yaml_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw ConfigError(path, {"cannot read file"});
  std::stringstream content;
  content << in.rdbuf();
  if (in.bad()) throw ConfigError(path, {"cannot read file"});
  try {
    return YAML::Load(content.str());
  } catch (const YAML::Exception& e) {
    throw ConfigError(path, {"line " + std::to_string(e.mark.line + 1) + ", column " +
                             std::to_string(e.mark.column + 1) + ": " + e.msg});
  }
}

void append_parameter_issues(const std::vector<ParameterIssue>& issues, const std::string& prefix,
                             std::vector<std::string>& problems) {
  for (const auto& issue : issues) problems.push_back(prefix + "." + issue.name + ": " + issue.problem);
}

// ---------------------------------------------------------------------------------------------
// public API

ConfigError::ConfigError(const std::string& file, std::vector<std::string> problems)
    : std::runtime_error(join_lines(file, problems)), problems_(std::move(problems)) {}

void apply_start_planner_parameters(const YAML::Node& node, const std::string& prefix, StartPlannerParameters& params,
                                    std::vector<std::string>& problems) {
  MapReader r(node, prefix, problems);
  if (!r.valid()) return;
  StartPlannerParameters& p = params;
  r.read("th_arrived_distance", p.th_arrived_distance);
  r.read("th_stopped_velocity", p.th_stopped_velocity);
  r.read("th_stopped_time", p.th_stopped_time);
  read_number_list(r, "collision_check_margins", "margins [m]", p.collision_check_margins);
  read_search_priority(r, p.search_priority);
  read_search_policy(r, p.search_policy);
  r.read("th_moving_object_velocity", p.th_moving_object_velocity);
  read_object_types(r, "object_types_to_check_for_path_generation", p.object_types_to_check_for_path_generation);
  r.read("center_line_path_interval", p.center_line_path_interval);
  r.read("forward_path_length", p.forward_path_length);
  r.read("check_shift_path_lane_departure", p.check_shift_path_lane_departure);
  r.read("allow_check_shift_path_lane_departure_override", p.allow_check_shift_path_lane_departure_override);
  r.read("lane_departure_check_expansion_margin", p.lane_departure_check_expansion_margin);
  r.read("shift_collision_check_distance_from_end", p.shift_collision_check_distance_from_end);
  r.read("minimum_shift_pull_out_distance", p.minimum_shift_pull_out_distance);
  r.read("lateral_jerk", p.lateral_jerk);
  r.read("lateral_acceleration_sampling_num", p.lateral_acceleration_sampling_num);
  r.read("minimum_lateral_acc", p.minimum_lateral_acc);
  r.read("maximum_lateral_acc", p.maximum_lateral_acc);
  r.read("maximum_curvature", p.maximum_curvature);
  r.read("end_pose_curvature_threshold", p.end_pose_curvature_threshold);
  r.read("maximum_longitudinal_acc", p.maximum_longitudinal_acc);

  r.read("enable_back", p.enable_back);
  r.read("max_back_distance", p.max_back_distance);
  r.read("backward_search_resolution", p.backward_search_resolution);
  r.read("collision_check_margin_from_front_object", p.collision_check_margin_from_front_object);
  r.read("ignore_distance_from_lane_end", p.ignore_distance_from_lane_end);
  r.read("backward_velocity", p.backward_velocity);

  r.read("geometric_pull_out_velocity", p.geometric_pull_out_velocity);
  r.read("arc_path_interval", p.arc_path_interval);
  r.read("lane_departure_margin", p.lane_departure_margin);
  r.read("geometric_pull_out_max_steer_angle_margin_scale", p.geometric_pull_out_max_steer_angle_margin_scale);
  r.read("divide_pull_out_path", p.divide_pull_out_path);
  r.read("geometric_collision_check_distance_from_end", p.geometric_collision_check_distance_from_end);

  r.read("clothoid_initial_velocity", p.clothoid_initial_velocity);
  r.read("clothoid_acceleration", p.clothoid_acceleration);
  read_number_list(r, "clothoid_max_steer_angles_deg", "steering angles [deg]", p.clothoid_max_steer_angles_deg);
  r.read("clothoid_max_steer_angle_rate_deg_per_sec", p.clothoid_max_steer_angle_rate_deg_per_sec);
  r.read("clothoid_collision_check_distance_from_end", p.clothoid_collision_check_distance_from_end);
  r.read("check_clothoid_path_lane_departure", p.check_clothoid_path_lane_departure);
  read_safety_sections(r, p);
  read_freespace(r, p.freespace_planner);
  r.finish(&start_planner_hint);
}

void apply_vehicle_info(const YAML::Node& node, const std::string& prefix, VehicleInfo& vehicle,
                        std::vector<std::string>& problems) {
  MapReader r(node, prefix, problems);
  if (!r.valid()) return;
  r.read("wheel_base", vehicle.wheel_base_m);
  r.read("wheel_tread", vehicle.wheel_tread_m);
  r.read("front_overhang", vehicle.front_overhang_m);
  r.read("rear_overhang", vehicle.rear_overhang_m);
  r.read("left_overhang", vehicle.left_overhang_m);
  r.read("right_overhang", vehicle.right_overhang_m);
  r.read("max_steer_angle", vehicle.max_steer_angle_rad);
  r.finish();
}

Config load_config(const std::string& path) {
  const YAML::Node doc = load_yaml_file(path);
  Config config;
  Problems problems;
  MapReader root(doc, "", problems);
  if (root.valid()) {
    apply_vehicle_info(root.get("vehicle"), "vehicle", config.vehicle, problems);
    apply_start_planner_parameters(root.get("start_planner"), "start_planner", config.start_planner, problems);
    apply_service(root.get("service"), config.service, problems);
    apply_dds(root.get("dds"), config.dds, problems);
    apply_map(root.get("map"), config.map, problems);
    root.finish();

    append_parameter_issues(validate_vehicle(config.vehicle), "vehicle", problems);
    append_parameter_issues(validate_parameters(config.start_planner), "start_planner", problems);
    validate_service(config.service, problems);
    validate_dds(config.dds, std::filesystem::path(path).parent_path(), problems);
    validate_map(config.map, std::filesystem::path(path).parent_path(), problems);
  }
  if (!problems.empty()) throw ConfigError(path, std::move(problems));
  return config;
}

}  // namespace pullout
