// Loading and validation of config/pullout.yaml.
#include "pullout/config/config.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

#include <unistd.h>

#include <gtest/gtest.h>

#include "pullout/model/names.hpp"

namespace pullout {
namespace {

const std::string kSourceDir = PULLOUT_SOURCE_DIR;
const std::string kShippedConfig = kSourceDir + "/config/pullout.yaml";

// A config file in a fresh temporary directory, with a profiles file beside it so that only the
// problems a test introduces are reported.
class ConfigFile {
 public:
  explicit ConfigFile(const std::string& text, bool with_profiles = true) {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::temp_directory_path() /
           ("pullout_test_config_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_ / "dds");
    if (with_profiles) std::ofstream(dir_ / "dds" / "loopback.xml") << "<dds/>\n";
    path_ = (dir_ / "pullout.yaml").string();
    std::ofstream(path_) << text;
  }
  ~ConfigFile() {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  const std::string& path() const { return path_; }
  std::filesystem::path dir() const { return dir_; }

 private:
  std::filesystem::path dir_;
  std::string path_;
};

constexpr const char* kMinimal = "dds: {profiles_file: dds/loopback.xml}\n";

// The problem lines of loading `text`, or an empty list when it loads.
std::vector<std::string> problems_of(const std::string& text) {
  ConfigFile file(text);
  try {
    load_config(file.path());
  } catch (const ConfigError& e) {
    return e.problems();
  }
  return {};
}

bool any_starts_with(const std::vector<std::string>& lines, const std::string& prefix) {
  return std::any_of(lines.begin(), lines.end(), [&](const std::string& l) { return l.rfind(prefix, 0) == 0; });
}

// The first planner this version of the core does not implement, if any.
std::optional<PlannerType> unavailable_planner() {
  for (const PlannerType p : {PlannerType::kGeometric, PlannerType::kClothoid, PlannerType::kFreespace}) {
    if (!planner_available(p)) return p;
  }
  return std::nullopt;
}

std::string dump(const std::vector<std::string>& lines) {
  std::string s;
  for (const auto& l : lines) s += l + "\n";
  return s;
}

TEST(Config, ShippedConfigLoadsWithTheStructDefaults) {
  const Config c = load_config(kShippedConfig);
  const Config d;
  EXPECT_DOUBLE_EQ(c.vehicle.wheel_base_m, d.vehicle.wheel_base_m);
  EXPECT_DOUBLE_EQ(c.vehicle.wheel_tread_m, d.vehicle.wheel_tread_m);
  EXPECT_DOUBLE_EQ(c.vehicle.front_overhang_m, d.vehicle.front_overhang_m);
  EXPECT_DOUBLE_EQ(c.vehicle.rear_overhang_m, d.vehicle.rear_overhang_m);
  EXPECT_DOUBLE_EQ(c.vehicle.left_overhang_m, d.vehicle.left_overhang_m);
  EXPECT_DOUBLE_EQ(c.vehicle.right_overhang_m, d.vehicle.right_overhang_m);
  EXPECT_DOUBLE_EQ(c.vehicle.max_steer_angle_rad, d.vehicle.max_steer_angle_rad);

  const StartPlannerParameters& p = c.start_planner;
  const StartPlannerParameters& q = d.start_planner;
  EXPECT_DOUBLE_EQ(p.th_arrived_distance, q.th_arrived_distance);
  EXPECT_DOUBLE_EQ(p.th_stopped_velocity, q.th_stopped_velocity);
  EXPECT_DOUBLE_EQ(p.th_stopped_time, q.th_stopped_time);
  EXPECT_EQ(p.collision_check_margins, q.collision_check_margins);
  EXPECT_EQ(p.search_priority, q.search_priority);
  EXPECT_EQ(p.search_policy, q.search_policy);
  EXPECT_DOUBLE_EQ(p.th_moving_object_velocity, q.th_moving_object_velocity);
  EXPECT_EQ(p.object_types_to_check_for_path_generation.check_unknown,
            q.object_types_to_check_for_path_generation.check_unknown);
  EXPECT_DOUBLE_EQ(p.center_line_path_interval, q.center_line_path_interval);
  EXPECT_DOUBLE_EQ(p.forward_path_length, q.forward_path_length);
  EXPECT_EQ(p.check_shift_path_lane_departure, q.check_shift_path_lane_departure);
  EXPECT_EQ(p.allow_check_shift_path_lane_departure_override, q.allow_check_shift_path_lane_departure_override);
  EXPECT_DOUBLE_EQ(p.lane_departure_check_expansion_margin, q.lane_departure_check_expansion_margin);
  EXPECT_DOUBLE_EQ(p.shift_collision_check_distance_from_end, q.shift_collision_check_distance_from_end);
  EXPECT_DOUBLE_EQ(p.minimum_shift_pull_out_distance, q.minimum_shift_pull_out_distance);
  EXPECT_DOUBLE_EQ(p.lateral_jerk, q.lateral_jerk);
  EXPECT_EQ(p.lateral_acceleration_sampling_num, q.lateral_acceleration_sampling_num);
  EXPECT_DOUBLE_EQ(p.minimum_lateral_acc, q.minimum_lateral_acc);
  EXPECT_DOUBLE_EQ(p.maximum_lateral_acc, q.maximum_lateral_acc);
  EXPECT_DOUBLE_EQ(p.maximum_curvature, q.maximum_curvature);
  EXPECT_DOUBLE_EQ(p.end_pose_curvature_threshold, q.end_pose_curvature_threshold);
  EXPECT_DOUBLE_EQ(p.maximum_longitudinal_acc, q.maximum_longitudinal_acc);
  EXPECT_EQ(p.enable_back, q.enable_back);
  EXPECT_DOUBLE_EQ(p.max_back_distance, q.max_back_distance);
  EXPECT_DOUBLE_EQ(p.backward_search_resolution, q.backward_search_resolution);
  EXPECT_DOUBLE_EQ(p.collision_check_margin_from_front_object, q.collision_check_margin_from_front_object);
  EXPECT_DOUBLE_EQ(p.ignore_distance_from_lane_end, q.ignore_distance_from_lane_end);
  EXPECT_DOUBLE_EQ(p.backward_velocity, q.backward_velocity);
  EXPECT_DOUBLE_EQ(p.geometric_pull_out_velocity, q.geometric_pull_out_velocity);
  EXPECT_DOUBLE_EQ(p.arc_path_interval, q.arc_path_interval);
  EXPECT_DOUBLE_EQ(p.lane_departure_margin, q.lane_departure_margin);
  EXPECT_DOUBLE_EQ(p.geometric_pull_out_max_steer_angle_margin_scale,
                   q.geometric_pull_out_max_steer_angle_margin_scale);
  EXPECT_EQ(p.divide_pull_out_path, q.divide_pull_out_path);
  EXPECT_DOUBLE_EQ(p.geometric_collision_check_distance_from_end, q.geometric_collision_check_distance_from_end);
  EXPECT_DOUBLE_EQ(p.clothoid_initial_velocity, q.clothoid_initial_velocity);
  EXPECT_DOUBLE_EQ(p.clothoid_acceleration, q.clothoid_acceleration);
  EXPECT_EQ(p.clothoid_max_steer_angles_deg, q.clothoid_max_steer_angles_deg);
  EXPECT_DOUBLE_EQ(p.clothoid_max_steer_angle_rate_deg_per_sec, q.clothoid_max_steer_angle_rate_deg_per_sec);
  EXPECT_DOUBLE_EQ(p.clothoid_collision_check_distance_from_end, q.clothoid_collision_check_distance_from_end);
  EXPECT_EQ(p.check_clothoid_path_lane_departure, q.check_clothoid_path_lane_departure);
  const FreespaceParameters& f = p.freespace_planner;
  const FreespaceParameters& g = q.freespace_planner;
  EXPECT_EQ(f.enable_freespace_planner, g.enable_freespace_planner);
  EXPECT_DOUBLE_EQ(f.end_pose_search_start_distance, g.end_pose_search_start_distance);
  EXPECT_DOUBLE_EQ(f.end_pose_search_end_distance, g.end_pose_search_end_distance);
  EXPECT_DOUBLE_EQ(f.end_pose_search_interval, g.end_pose_search_interval);
  EXPECT_DOUBLE_EQ(f.velocity, g.velocity);
  EXPECT_DOUBLE_EQ(f.vehicle_shape_margin, g.vehicle_shape_margin);
  EXPECT_DOUBLE_EQ(f.time_limit, g.time_limit);
  EXPECT_DOUBLE_EQ(f.max_turning_ratio, g.max_turning_ratio);
  EXPECT_EQ(f.turning_steps, g.turning_steps);
  EXPECT_EQ(f.search_configs.theta_size, g.search_configs.theta_size);
  EXPECT_DOUBLE_EQ(f.search_configs.angle_goal_range, g.search_configs.angle_goal_range);
  EXPECT_DOUBLE_EQ(f.search_configs.lateral_goal_range, g.search_configs.lateral_goal_range);
  EXPECT_DOUBLE_EQ(f.search_configs.longitudinal_goal_range, g.search_configs.longitudinal_goal_range);
  EXPECT_DOUBLE_EQ(f.search_configs.curve_weight, g.search_configs.curve_weight);
  EXPECT_DOUBLE_EQ(f.search_configs.reverse_weight, g.search_configs.reverse_weight);
  EXPECT_DOUBLE_EQ(f.search_configs.direction_change_weight, g.search_configs.direction_change_weight);
  EXPECT_EQ(f.costmap_configs.obstacle_threshold, g.costmap_configs.obstacle_threshold);
  EXPECT_DOUBLE_EQ(f.costmap_configs.resolution, g.costmap_configs.resolution);
  EXPECT_EQ(f.astar.use_back, g.astar.use_back);
  EXPECT_DOUBLE_EQ(f.astar.distance_heuristic_weight, g.astar.distance_heuristic_weight);
  EXPECT_DOUBLE_EQ(f.astar.expansion_distance, g.astar.expansion_distance);
  EXPECT_DOUBLE_EQ(f.astar.narrow_heuristic_penalty, g.astar.narrow_heuristic_penalty);

  EXPECT_EQ(c.service.worker_threads, d.service.worker_threads);
  EXPECT_DOUBLE_EQ(c.service.default_deadline_ms, d.service.default_deadline_ms);
  EXPECT_EQ(c.service.log_level, d.service.log_level);
  EXPECT_EQ(c.service.limits.max_lanes, d.service.limits.max_lanes);
  EXPECT_EQ(c.service.limits.max_points_per_line, d.service.limits.max_points_per_line);
  EXPECT_EQ(c.service.limits.max_objects, d.service.limits.max_objects);
  EXPECT_EQ(c.service.limits.max_polygon_points, d.service.limits.max_polygon_points);
  EXPECT_EQ(c.service.limits.max_predicted_paths, d.service.limits.max_predicted_paths);
  EXPECT_EQ(c.service.limits.max_predicted_path_points, d.service.limits.max_predicted_path_points);
  EXPECT_EQ(c.service.limits.max_route_lanelets, d.service.limits.max_route_lanelets);
  EXPECT_EQ(c.service.limits.max_grid_cells, d.service.limits.max_grid_cells);
  EXPECT_DOUBLE_EQ(c.service.limits.max_deadline_ms, d.service.limits.max_deadline_ms);

  EXPECT_EQ(c.dds.domain_id, d.dds.domain_id);
  EXPECT_EQ(c.dds.participant_profile, d.dds.participant_profile);
  // Resolved relative to the config file.
  EXPECT_EQ(std::filesystem::path(c.dds.profiles_file),
            std::filesystem::path(kSourceDir + "/config/dds/loopback.xml").lexically_normal());
}

TEST(Config, ShippedConfigSetsEveryKey) {
  // Every key the loader knows appears in the shipped file: removing any one of them must still
  // load (keys are optional), and the file mentions each by name.
  std::ifstream in(kShippedConfig);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (const char* key : {"wheel_base",
                          "wheel_tread",
                          "front_overhang",
                          "rear_overhang",
                          "left_overhang",
                          "right_overhang",
                          "max_steer_angle",
                          "th_arrived_distance",
                          "th_stopped_velocity",
                          "th_stopped_time",
                          "collision_check_margins",
                          "search_priority",
                          "search_policy",
                          "th_moving_object_velocity",
                          "object_types_to_check_for_path_generation",
                          "check_car",
                          "check_truck",
                          "check_bus",
                          "check_trailer",
                          "check_bicycle",
                          "check_motorcycle",
                          "check_pedestrian",
                          "check_unknown",
                          "center_line_path_interval",
                          "forward_path_length",
                          "check_shift_path_lane_departure",
                          "allow_check_shift_path_lane_departure_override",
                          "lane_departure_check_expansion_margin",
                          "shift_collision_check_distance_from_end",
                          "minimum_shift_pull_out_distance",
                          "lateral_jerk",
                          "lateral_acceleration_sampling_num",
                          "minimum_lateral_acc",
                          "maximum_lateral_acc",
                          "maximum_curvature",
                          "end_pose_curvature_threshold",
                          "maximum_longitudinal_acc",
                          "enable_back",
                          "max_back_distance",
                          "backward_search_resolution",
                          "collision_check_margin_from_front_object",
                          "ignore_distance_from_lane_end",
                          "backward_velocity",
                          "geometric_pull_out_velocity",
                          "arc_path_interval",
                          "lane_departure_margin",
                          "geometric_pull_out_max_steer_angle_margin_scale",
                          "divide_pull_out_path",
                          "geometric_collision_check_distance_from_end",
                          "clothoid_initial_velocity",
                          "clothoid_acceleration",
                          "clothoid_max_steer_angles_deg",
                          "clothoid_max_steer_angle_rate_deg_per_sec",
                          "clothoid_collision_check_distance_from_end",
                          "check_clothoid_path_lane_departure",
                          "freespace_planner",
                          "enable_freespace_planner",
                          "end_pose_search_start_distance",
                          "end_pose_search_end_distance",
                          "end_pose_search_interval",
                          "velocity",
                          "vehicle_shape_margin",
                          "time_limit",
                          "max_turning_ratio",
                          "turning_steps",
                          "search_configs",
                          "theta_size",
                          "angle_goal_range",
                          "lateral_goal_range",
                          "longitudinal_goal_range",
                          "curve_weight",
                          "reverse_weight",
                          "direction_change_weight",
                          "costmap_configs",
                          "obstacle_threshold",
                          "resolution",
                          "astar",
                          "use_back",
                          "distance_heuristic_weight",
                          "expansion_distance",
                          "narrow_heuristic_penalty",
                          "worker_threads",
                          "default_deadline_ms",
                          "log_level",
                          "max_lanes",
                          "max_points_per_line",
                          "max_objects",
                          "max_polygon_points",
                          "max_predicted_paths",
                          "max_predicted_path_points",
                          "max_route_lanelets",
                          "max_grid_cells",
                          "max_deadline_ms",
                          "domain_id",
                          "profiles_file",
                          "participant_profile"}) {
    EXPECT_NE(text.find(std::string(key) + ":"), std::string::npos) << key;
  }
}

TEST(Config, MinimalConfigLoads) { EXPECT_TRUE(problems_of(kMinimal).empty()) << dump(problems_of(kMinimal)); }

TEST(Config, UnknownKeyIsNamed) {
  const auto p = problems_of(std::string(kMinimal) + "start_planner: {lateral_jerk: 0.6, lateral_jurk: 0.5}\n");
  ASSERT_EQ(p.size(), 1u) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "start_planner.lateral_jurk: unknown key")) << dump(p);
}

TEST(Config, UnknownSectionAndNestedKeyAreNamed) {
  const auto p = problems_of(std::string(kMinimal) +
                             "planner: {}\n"
                             "service: {limits: {max_lane: 3}}\n"
                             "start_planner:\n  object_types_to_check_for_path_generation: {check_tram: true}\n");
  EXPECT_TRUE(any_starts_with(p, "planner: unknown key")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "service.limits.max_lane: unknown key")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "start_planner.object_types_to_check_for_path_generation.check_tram: unknown key"))
      << dump(p);
}

TEST(Config, AutowareOnlyKeyGetsAClearMessage) {
  const auto p = problems_of(std::string(kMinimal) + "start_planner: {turn_signal_on_centerline_start: RIGHT}\n");
  ASSERT_EQ(p.size(), 1u) << dump(p);
  EXPECT_NE(p[0].find("start_planner.turn_signal_on_centerline_start: Autoware parameter not supported"),
            std::string::npos)
      << dump(p);
}

TEST(Config, WrongTypeIsNamed) {
  const auto p = problems_of(std::string(kMinimal) +
                             "vehicle: {wheel_base: long}\n"
                             "start_planner:\n"
                             "  lateral_acceleration_sampling_num: 2.5\n"
                             "  check_shift_path_lane_departure: maybe\n"
                             "  collision_check_margins: 1.0\n"
                             "service: {worker_threads: [1]}\n");
  EXPECT_TRUE(any_starts_with(p, "vehicle.wheel_base: expected a number, got 'long'")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "start_planner.lateral_acceleration_sampling_num: expected an integer")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "start_planner.check_shift_path_lane_departure: expected true or false")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "start_planner.collision_check_margins: expected a list")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "service.worker_threads: expected an integer")) << dump(p);
  EXPECT_EQ(p.size(), 5u) << dump(p);
}

TEST(Config, ProblemLinesCarryTheFileAndLine) {
  ConfigFile file(std::string(kMinimal) + "vehicle:\n  wheel_base: long\n");
  try {
    load_config(file.path());
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind(file.path() + ": vehicle.wheel_base: expected a number", 0), 0u) << what;
    EXPECT_NE(what.find("(line 3)"), std::string::npos) << what;
  }
}

TEST(Config, OutOfRangeIsNamed) {
  const auto p = problems_of(
      "vehicle: {max_steer_angle: 2.0}\n"
      "start_planner: {lateral_jerk: -1, collision_check_margins: [1.0, -0.5],"
      " minimum_lateral_acc: 0.6, maximum_lateral_acc: 0.5}\n"
      "service: {worker_threads: 0, default_deadline_ms: 20000, log_level: loud}\n"
      "dds: {domain_id: 300, profiles_file: dds/loopback.xml}\n");
  EXPECT_TRUE(any_starts_with(p, "vehicle.max_steer_angle: must be in")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "start_planner.lateral_jerk: must be > 0")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "start_planner.collision_check_margins[1]: must be in")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "start_planner.maximum_lateral_acc: must be >= minimum_lateral_acc")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "service.worker_threads: must be in [1, 64]")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "service.default_deadline_ms: must be in")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "service.log_level: unknown level 'loud'")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "dds.domain_id: must be in [0, 232]")) << dump(p);
}

TEST(Config, NonFiniteNumberIsRejected) {
  const auto p = problems_of(std::string(kMinimal) + "start_planner: {th_arrived_distance: .nan}\n");
  EXPECT_TRUE(any_starts_with(p, "start_planner.th_arrived_distance: must be a finite number")) << dump(p);
}

TEST(Config, SeveralProblemsAreReportedTogether) {
  const auto p = problems_of(
      "vehicle: {wheel_base: -1}\n"
      "start_planner: {bogus: 1, lateral_jerk: x}\n"
      "service: {worker_threads: 100}\n");
  EXPECT_TRUE(any_starts_with(p, "vehicle.wheel_base:")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "start_planner.bogus: unknown key")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "start_planner.lateral_jerk: expected a number")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "service.worker_threads:")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "dds.profiles_file: required")) << dump(p);
  EXPECT_EQ(p.size(), 5u) << dump(p);
}

TEST(Config, SearchPriorityAcceptsAutowareAndModelNames) {
  ConfigFile upper(std::string(kMinimal) + "start_planner: {search_priority: [\"SHIFT\"]}\n");
  EXPECT_EQ(load_config(upper.path()).start_planner.search_priority, std::vector<PlannerType>{PlannerType::kShift});
  ConfigFile lower(std::string(kMinimal) +
                   "start_planner: {search_priority: [shift], search_policy: distance_priority}\n");
  const Config c = load_config(lower.path());
  EXPECT_EQ(c.start_planner.search_priority, std::vector<PlannerType>{PlannerType::kShift});
  EXPECT_EQ(c.start_planner.search_policy, SearchPolicy::kDistancePriority);
}

TEST(Config, SearchPriorityProblems) {
  const auto p =
      problems_of(std::string(kMinimal) +
                  "start_planner: {search_priority: [SHIFT, GEOMETRIC, teleport], search_policy: fastest}\n");
  EXPECT_TRUE(any_starts_with(p, "start_planner.search_priority[2]: unknown planner 'teleport'")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "start_planner.search_policy: unknown policy 'fastest'")) << dump(p);

  if (const auto missing = unavailable_planner()) {
    const std::string name = to_string(*missing);
    const auto q = problems_of(std::string(kMinimal) + "start_planner: {search_priority: [SHIFT, " + name + "]}\n");
    ASSERT_EQ(q.size(), 1u) << dump(q);
    EXPECT_TRUE(any_starts_with(
        q, "start_planner.search_priority[1]: planner '" + name + "' is not available in this version (available: "))
        << dump(q);
  }

  const auto r = problems_of(std::string(kMinimal) + "start_planner: {search_priority: [shift, SHIFT]}\n");
  EXPECT_TRUE(any_starts_with(r, "start_planner.search_priority[1]: planner 'shift' is listed twice")) << dump(r);

  const auto s = problems_of(std::string(kMinimal) + "start_planner: {search_priority: []}\n");
  EXPECT_TRUE(any_starts_with(s, "start_planner.search_priority: must list at least one planner")) << dump(s);

  const auto t = problems_of(std::string(kMinimal) + "start_planner: {search_priority: [stop]}\n");
  EXPECT_TRUE(any_starts_with(t, "start_planner.search_priority[0]: 'stop' is not a planner")) << dump(t);
}

TEST(Config, FreespaceKeysAreReadAndChecked) {
  ConfigFile ok(std::string(kMinimal) +
                "start_planner:\n  freespace_planner:\n    enable_freespace_planner: false\n"
                "    search_configs: {theta_size: 72}\n    astar: {use_back: false}\n");
  const Config c = load_config(ok.path());
  EXPECT_FALSE(c.start_planner.freespace_planner.enable_freespace_planner);
  EXPECT_EQ(c.start_planner.freespace_planner.search_configs.theta_size, 72);
  EXPECT_FALSE(c.start_planner.freespace_planner.astar.use_back);

  const auto p = problems_of(std::string(kMinimal) +
                             "start_planner:\n  freespace_planner:\n    time_limit: -1\n"
                             "    end_pose_search_start_distance: 30\n    end_pose_search_end_distance: 20\n"
                             "    search_configs: {theta_size: 3, bogus: 1}\n"
                             "    freespace_planner_algorithm: rrtstar\n");
  EXPECT_TRUE(any_starts_with(p, "start_planner.freespace_planner.time_limit: must be in")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "start_planner.freespace_planner.end_pose_search_end_distance: must be >="))
      << dump(p);
  EXPECT_TRUE(any_starts_with(p, "start_planner.freespace_planner.search_configs.theta_size: must be in")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "start_planner.freespace_planner.search_configs.bogus: unknown key")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "start_planner.freespace_planner.freespace_planner_algorithm: Autoware parameter"))
      << dump(p);
  EXPECT_EQ(p.size(), 5u) << dump(p);
}

TEST(Config, MissingProfilesFileIsAnError) {
  ConfigFile file("dds: {profiles_file: dds/nowhere.xml}\n");
  try {
    load_config(file.path());
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    ASSERT_EQ(e.problems().size(), 1u);
    EXPECT_EQ(e.problems()[0].rfind("dds.profiles_file: file not found", 0), 0u) << e.what();
  }
}

TEST(Config, DuplicateKeyIsAnError) {
  const auto p = problems_of(std::string(kMinimal) + "vehicle:\n  wheel_base: 2.5\n  wheel_base: 3.0\n");
  EXPECT_TRUE(any_starts_with(p, "vehicle.wheel_base: duplicate key")) << dump(p);
}

TEST(Config, SyntaxErrorAndUnreadableFile) {
  const auto p = problems_of("vehicle: {wheel_base: [1, 2\n");
  ASSERT_EQ(p.size(), 1u);
  EXPECT_EQ(p[0].rfind("line ", 0), 0u) << p[0];
  EXPECT_THROW(load_config("/nonexistent/pullout.yaml"), ConfigError);

  const auto q = problems_of("- just\n- a list\n");
  EXPECT_TRUE(any_starts_with(q, "document: expected a mapping")) << dump(q);
}

TEST(Config, EmptyFileUsesDefaultsButNeedsTheProfilesFile) {
  const auto p = problems_of("");
  ASSERT_EQ(p.size(), 1u) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "dds.profiles_file: required")) << dump(p);
}

TEST(Config, ValidatorsAcceptDefaults) {
  EXPECT_TRUE(validate_parameters(StartPlannerParameters{}).empty());
  EXPECT_TRUE(validate_vehicle(VehicleInfo{}).empty());
}

TEST(Config, ObjectTypesToCheckIncludes) {
  ObjectTypesToCheck t;
  t.check_pedestrian = false;
  t.check_unknown = false;
  EXPECT_TRUE(t.includes(ObjectClass::kCar));
  EXPECT_TRUE(t.includes(ObjectClass::kTrailer));
  EXPECT_FALSE(t.includes(ObjectClass::kPedestrian));
  EXPECT_FALSE(t.includes(ObjectClass::kUnknown));
}

}  // namespace
}  // namespace pullout

namespace pullout {
namespace {

TEST(ConfigMap, PathIsResolvedRelativeToTheConfigFile) {
  ConfigFile file(std::string(kMinimal) + "map: {path: maps/town.osm}\n");
  std::filesystem::create_directories(file.dir() / "maps");
  std::ofstream(file.dir() / "maps" / "town.osm") << "<osm/>\n";
  const Config c = load_config(file.path());
  EXPECT_EQ(c.map.path, (file.dir() / "maps" / "town.osm").string());
}

TEST(ConfigMap, EmptyOrAbsentMeansNoMap) {
  EXPECT_TRUE(load_config(kShippedConfig).map.path.empty());
  EXPECT_TRUE(problems_of(std::string(kMinimal) + "map: {path: \"\"}\n").empty());
}

TEST(ConfigMap, MissingFileAndUnknownKeysAreNamed) {
  auto p = problems_of(std::string(kMinimal) + "map: {path: nowhere.osm}\n");
  EXPECT_TRUE(any_starts_with(p, "map.path: file not found")) << dump(p);
  p = problems_of(std::string(kMinimal) + "map: {path: \"\", origin: 3}\n");
  EXPECT_TRUE(any_starts_with(p, "map.origin: unknown key")) << dump(p);
  p = problems_of(std::string(kMinimal) + "map: {path: [1, 2]}\n");
  EXPECT_TRUE(any_starts_with(p, "map.path:")) << dump(p);
}

TEST(Config, SafetySectionsLoadWithAutowareNames) {
  const Config d;
  const Config shipped = load_config(kShippedConfig);
  const StartPlannerParameters& s = shipped.start_planner;
  EXPECT_DOUBLE_EQ(s.path_safety_check.safety_check_params.rss_params.rear_vehicle_reaction_time, 2.0);
  EXPECT_DOUBLE_EQ(s.path_safety_check.ego_predicted_path.delay_until_departure, 1.0);
  EXPECT_DOUBLE_EQ(s.path_safety_check.target_filtering.ignore_object_velocity_threshold, 0.25);
  EXPECT_FALSE(s.path_safety_check.target_filtering.object_types_to_check.check_unknown);
  EXPECT_DOUBLE_EQ(s.surround_moving_obstacle_check.search_radius, 10.0);
  EXPECT_DOUBLE_EQ(s.stop_condition.maximum_jerk_for_stop, d.start_planner.stop_condition.maximum_jerk_for_stop);
  EXPECT_DOUBLE_EQ(s.backward_path_update_duration, 3.0);
  EXPECT_FALSE(s.skip_rear_vehicle_check);

  ConfigFile file(std::string(kMinimal) +
                  "start_planner:\n"
                  "  skip_rear_vehicle_check: true\n"
                  "  prepare_time_before_start: 1.5\n"
                  "  path_safety_check:\n"
                  "    safety_check_params:\n"
                  "      rss_params: {rear_vehicle_reaction_time: 1.2, extended_polygon_policy: rectangle}\n"
                  "  stop_condition: {maximum_deceleration_for_stop: 2.0}\n");
  const Config c = load_config(file.path());
  EXPECT_TRUE(c.start_planner.skip_rear_vehicle_check);
  EXPECT_DOUBLE_EQ(c.start_planner.prepare_time_before_start, 1.5);
  EXPECT_DOUBLE_EQ(c.start_planner.path_safety_check.safety_check_params.rss_params.rear_vehicle_reaction_time, 1.2);
  EXPECT_EQ(c.start_planner.path_safety_check.safety_check_params.rss_params.extended_polygon_policy,
            ExtendedPolygonPolicy::kRectangle);
  EXPECT_DOUBLE_EQ(c.start_planner.stop_condition.maximum_deceleration_for_stop, 2.0);
}

TEST(Config, SafetyValuesAreRangeChecked) {
  const auto p = problems_of(std::string(kMinimal) +
                             "start_planner:\n"
                             "  path_safety_check:\n"
                             "    ego_predicted_path: {time_resolution: 0.0}\n"
                             "    safety_check_params: {rss_params: {rear_vehicle_deceleration: 1.0}}\n"
                             "  stop_condition: {maximum_jerk_for_stop: -1.0, jerk: 1}\n");
  EXPECT_TRUE(any_starts_with(p, "start_planner.path_safety_check.ego_predicted_path.time_resolution: must be in"))
      << dump(p);
  EXPECT_TRUE(any_starts_with(
      p, "start_planner.path_safety_check.safety_check_params.rss_params.rear_vehicle_deceleration: must be in"))
      << dump(p);
  EXPECT_TRUE(any_starts_with(p, "start_planner.stop_condition.maximum_jerk_for_stop: must be in")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "start_planner.stop_condition.jerk: unknown key")) << dump(p);
}

}  // namespace
}  // namespace pullout
