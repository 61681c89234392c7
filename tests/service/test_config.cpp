// Loading and validation of config/pullout.yaml.
#include "pullout/config/config.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

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
  for (const PlannerType p : kSearchPlanners) {
    if (!planner_available(p)) return p;
  }
  return std::nullopt;
}

std::string dump(const std::vector<std::string>& lines) {
  std::string s;
  for (const auto& l : lines) s += l + "\n";
  return s;
}

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

std::vector<std::string> split_lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// The dotted paths of the leaves (scalars and lists) of a YAML mapping.
void collect_leaves(const YAML::Node& node, const std::string& prefix, std::vector<std::string>& out) {
  for (const auto& entry : node) {
    const std::string path = prefix.empty() ? entry.first.Scalar() : prefix + "." + entry.first.Scalar();
    if (entry.second.IsMap()) {
      collect_leaves(entry.second, path, out);
    } else {
      out.push_back(path);
    }
  }
}

TEST(ConfigTable, ShippedFileIsTheDocumentedConfig) {
  // config/pullout.yaml is generated from the tables: same keys, same order, same defaults, units,
  // allowed values and comments. A key added to a table (or a struct default changed) without
  // regenerating the file fails here, and so does a key added to the file only.
  const std::vector<std::string> shipped = split_lines(read_text(kShippedConfig));
  const std::vector<std::string> generated = split_lines(documented_config());
  const std::size_t n = std::min(shipped.size(), generated.size());
  std::size_t first = n;
  for (std::size_t i = 0; i < n; ++i) {
    if (shipped[i] != generated[i]) {
      first = i;
      break;
    }
  }
  if (first == n && shipped.size() == generated.size()) return;
  ADD_FAILURE() << "config/pullout.yaml differs from the config tables at line " << first + 1
                << ":\n  file:   " << (first < shipped.size() ? shipped[first] : "(end of file)")
                << "\n  tables: " << (first < generated.size() ? generated[first] : "(end)")
                << "\nRegenerate it: build/service/pullout_service --print-config > config/pullout.yaml";
}

TEST(ConfigTable, ShippedFileReadsBackToTheDefaults) {
  // Every value written in the file reads back as the struct default it was written from (the
  // documented text of what was read equals the documented text of the defaults).
  const Config loaded = load_config(kShippedConfig);
  // The shipped config runs on the built-in loopback profiles (config/dds/loopback.xml).
  EXPECT_TRUE(loaded.dds.profiles_file.empty()) << loaded.dds.profiles_file;
  EXPECT_EQ(documented_config(loaded), documented_config());
}

TEST(ConfigTable, DocumentedValuesAreWhatWasRead) {
  // The documented text shows the values of the config it is given, not constants.
  ConfigFile file(std::string(kMinimal) +
                  "start_planner:\n  lateral_jerk: 0.7\n  search_priority: [geometric]\n"
                  "  path_safety_check: {target_filtering: {object_types_to_check: {check_bus: false}}}\n");
  const std::string text = documented_config(load_config(file.path()));
  EXPECT_NE(text.find("\n  lateral_jerk: 0.7 "), std::string::npos) << text;
  EXPECT_NE(text.find("\n  search_priority: [GEOMETRIC] "), std::string::npos) << text;
  EXPECT_NE(text.find("\n        check_bus: false"), std::string::npos) << text;
  EXPECT_EQ(documented_config().find("lateral_jerk: 0.7 "), std::string::npos);
}

TEST(ConfigTable, EveryDocumentedKeyIsReadAndTypeChecked) {
  // Each key of the documented file, given a mapping instead of its value, gives exactly one
  // problem naming that key: every key the file documents is one the loader reads.
  const std::string documented = documented_config();
  std::vector<std::string> leaves;
  collect_leaves(YAML::Load(documented), "", leaves);
  ASSERT_GT(leaves.size(), 100u);
  for (const std::string& leaf : leaves) {
    YAML::Node root = YAML::Load(documented);
    std::vector<YAML::Node> chain{root};  // copies share the nodes; no assignment between them
    std::size_t start = 0;
    while (true) {
      const std::size_t dot = leaf.find('.', start);
      chain.push_back(chain.back()[leaf.substr(start, dot == std::string::npos ? std::string::npos : dot - start)]);
      if (dot == std::string::npos) break;
      start = dot + 1;
    }
    chain.back() = YAML::Load("{not_a_value: 1}");
    YAML::Emitter out;
    out << root;
    const auto p = problems_of(out.c_str());
    ASSERT_EQ(p.size(), 1u) << leaf << "\n" << dump(p);
    EXPECT_EQ(p[0].rfind(leaf + ": expected ", 0), 0u) << leaf << "\n" << dump(p);
  }
}

TEST(ConfigTable, DefaultsAreAllowedValues) { EXPECT_TRUE(check_config(Config{}).empty()) << dump(check_config({})); }

TEST(ConfigTable, CheckConfigNamesEveryBadMember) {
  Config c;
  c.vehicle.max_steer_angle_rad = 2.0;
  c.start_planner.lateral_jerk = -1.0;
  c.start_planner.collision_check_margins = {1.0, -0.5};
  c.start_planner.path_safety_check.safety_check_params.rss_params.rear_vehicle_deceleration = 1.0;
  c.start_planner.freespace_planner.search_configs.theta_size = 3;
  c.start_planner.minimum_lateral_acc = 0.6;  // > maximum_lateral_acc: between keys
  c.service.limits.max_objects = 0;
  c.dds.participant_profile.clear();
  const auto p = check_config(c);
  EXPECT_TRUE(any_starts_with(p, "vehicle.max_steer_angle: must be in [0.01, 1.5], got 2")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "start_planner.lateral_jerk: must be > 0, got -1")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "start_planner.collision_check_margins[1]: must be in [0, 10], got -0.5")) << dump(p);
  EXPECT_TRUE(any_starts_with(
      p, "start_planner.path_safety_check.safety_check_params.rss_params.rear_vehicle_deceleration: must be in"))
      << dump(p);
  EXPECT_TRUE(any_starts_with(p, "start_planner.freespace_planner.search_configs.theta_size: must be in [8, 720]"))
      << dump(p);
  EXPECT_TRUE(any_starts_with(p, "start_planner.maximum_lateral_acc: must be >= minimum_lateral_acc")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "service.limits.max_objects: must be >= 1, got 0")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "dds.participant_profile: must not be empty")) << dump(p);
  EXPECT_EQ(p.size(), 8u) << dump(p);
}

// The margins are tried largest first and the last is the least the backward search keeps: a
// list out of order is refused, naming the first entry out of place.
TEST(ConfigTable, CollisionCheckMarginsMustDecrease) {
  Config c;
  c.start_planner.collision_check_margins = {2.0, 0.5, 1.0};
  auto p = check_config(c);
  ASSERT_EQ(p.size(), 1u) << dump(p);
  EXPECT_EQ(p[0],
            "start_planner.collision_check_margins[2]: must be below the one before (0.5; tried largest first), got 1");
  c.start_planner.collision_check_margins = {1.0, 1.0};
  EXPECT_EQ(check_config(c).size(), 1u);
  c.start_planner.collision_check_margins = {2.0, 1.0, 0.5, 0.1};
  EXPECT_TRUE(check_config(c).empty());
}

TEST(ConfigTable, OutOfRangeValueInAFileCarriesItsLine) {
  const auto p = problems_of(std::string(kMinimal) + "start_planner:\n  lateral_jerk: 0.4\n  max_back_distance: 500\n");
  ASSERT_EQ(p.size(), 1u) << dump(p);
  EXPECT_EQ(p[0], "start_planner.max_back_distance: must be in [0, 200], got 500 (line 4)");
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

TEST(Config, FreespaceAlgorithmIsAutowaresKey) {
  ConfigFile rrt(std::string(kMinimal) +
                 "start_planner:\n  freespace_planner:\n    freespace_planner_algorithm: rrtstar\n");
  EXPECT_EQ(load_config(rrt.path()).start_planner.freespace_planner.freespace_planner_algorithm, "rrtstar");
  EXPECT_EQ(Config{}.start_planner.freespace_planner.freespace_planner_algorithm, "astar");
  const auto p = problems_of(std::string(kMinimal) +
                             "start_planner:\n  freespace_planner:\n    freespace_planner_algorithm: dijkstra\n");
  ASSERT_EQ(p.size(), 1u) << dump(p);
  EXPECT_TRUE(
      any_starts_with(p, "start_planner.freespace_planner.freespace_planner_algorithm: unknown value 'dijkstra'"))
      << dump(p);
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
  EXPECT_TRUE(any_starts_with(p, "service.log_level: unknown value 'loud' (expected trace, debug,")) << dump(p);
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
  EXPECT_EQ(p.size(), 4u) << dump(p);
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
                             "    rrtstar: {enable_update: true}\n");
  EXPECT_TRUE(any_starts_with(p, "start_planner.freespace_planner.time_limit: must be in")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "start_planner.freespace_planner.end_pose_search_end_distance: must be >="))
      << dump(p);
  EXPECT_TRUE(any_starts_with(p, "start_planner.freespace_planner.search_configs.theta_size: must be in")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "start_planner.freespace_planner.search_configs.bogus: unknown key")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "start_planner.freespace_planner.rrtstar: Autoware parameter")) << dump(p);
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

TEST(Config, EmptyFileUsesTheDefaults) {
  // No profiles file beside it either: the default is the built-in loopback profiles.
  ConfigFile file("", /*with_profiles=*/false);
  const Config c = load_config(file.path());
  EXPECT_TRUE(c.dds.profiles_file.empty()) << c.dds.profiles_file;
  EXPECT_EQ(documented_config(c), documented_config(Config{}));
}

TEST(Config, EmptyProfilesFileMeansTheBuiltInProfiles) {
  EXPECT_TRUE(problems_of("dds: {profiles_file: \"\"}\n").empty());
}

TEST(Config, ValidatorsAcceptDefaults) { EXPECT_TRUE(validate_parameters(StartPlannerParameters{}).empty()); }

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

namespace pullout {
namespace {

TEST(VehicleProfiles, TheShippedProfilesAreACarAVanAndABus) {
  const Config c = load_config(std::string(PULLOUT_SOURCE_DIR) + "/config/pullout.yaml");
  ASSERT_EQ(c.vehicle_profiles.size(), 3u);
  EXPECT_EQ(c.vehicle_profiles.at("car"), VehicleInfo{});
  EXPECT_NEAR(c.vehicle_profiles.at("bus").length_m(), 12.0, 1e-9);
  EXPECT_GT(c.vehicle_profiles.at("van").length_m(), c.vehicle_profiles.at("car").length_m());
}

TEST(VehicleProfiles, AFileReplacesTheProfilesAndKeysLeftOutTakeTheirDefaults) {
  const auto c = [] {
    ConfigFile file(std::string(kMinimal) + "vehicle_profiles:\n  tram: {wheel_base: 9.0, rear_overhang: 4.0}\n");
    return load_config(file.path());
  }();
  ASSERT_EQ(c.vehicle_profiles.size(), 1u);
  EXPECT_DOUBLE_EQ(c.vehicle_profiles.at("tram").wheel_base_m, 9.0);
  EXPECT_DOUBLE_EQ(c.vehicle_profiles.at("tram").wheel_tread_m, VehicleInfo{}.wheel_tread_m);
}

TEST(VehicleProfiles, BadProfilesAreNamed) {
  const auto p =
      problems_of(std::string(kMinimal) + "vehicle_profiles:\n  bus: {wheel_base: 0, colour: red}\n  'a b': {}\n");
  const std::string all = dump(p);
  EXPECT_NE(all.find("vehicle_profiles.bus.wheel_base"), std::string::npos) << all;
  EXPECT_NE(all.find("vehicle_profiles.bus.colour"), std::string::npos) << all;
  EXPECT_NE(all.find("profile name 'a b'"), std::string::npos) << all;
  EXPECT_FALSE(problems_of(std::string(kMinimal) + "vehicle_profiles: [bus]\n").empty());
}

}  // namespace
}  // namespace pullout
