// Loading of scenario files.
#include "pullout/config/scenario.hpp"

#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "pullout/geometry/angle.hpp"
#include "pullout/maps/lanelet_map.hpp"

namespace pullout {
namespace {

const std::string kScenarioDir = std::string(PULLOUT_SOURCE_DIR) + "/tests/scenarios";

class ScenarioFile {
 public:
  explicit ScenarioFile(const std::string& text) {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = (std::filesystem::temp_directory_path() /
             ("pullout_test_scenario_" + std::string(info->name()) + "_" + std::to_string(::getpid()) + ".yaml"))
                .string();
    std::ofstream(path_) << text;
  }
  ~ScenarioFile() {
    std::error_code ec;
    std::filesystem::remove(path_, ec);
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

constexpr const char* kLanes =
    "lanes:\n"
    "  - {id: 1, subtype: road, left_bound: [[0, 1.75], [100, 1.75]], right_bound: [[0, -1.75], [100, -1.75]]}\n";
constexpr const char* kPoses = "start: {x: 10, y: 0}\ngoal: {x: 90, y: 0}\n";

std::vector<std::string> problems_of(const std::string& text) {
  ScenarioFile file(text);
  try {
    load_scenario(file.path());
  } catch (const ConfigError& e) {
    return e.problems();
  }
  return {};
}

std::vector<std::string> problems_of_file(const std::string& path) {
  try {
    load_scenario(path);
  } catch (const ConfigError& e) {
    return e.problems();
  }
  return {};
}

bool any_starts_with(const std::vector<std::string>& lines, const std::string& prefix) {
  return std::any_of(lines.begin(), lines.end(), [&](const std::string& l) { return l.rfind(prefix, 0) == 0; });
}

std::string dump(const std::vector<std::string>& lines) {
  std::string s;
  for (const auto& l : lines) s += l + "\n";
  return s;
}

// The shared scenario (tests/scenarios/straight_shoulder.yaml): a 100 m straight road, lane 1 at
// y in [-1.75, 1.75], a shoulder lane 2 at y in [1.75, 4.75], start on the shoulder centre.
TEST(Scenario, StraightShoulderLoads) {
  const Scenario s = load_scenario(kScenarioDir + "/straight_shoulder.yaml");
  EXPECT_FALSE(s.description.empty());
  const PullOutRequest& r = s.request;
  EXPECT_FALSE(r.vehicle_id.empty());
  ASSERT_EQ(r.lanes.size(), 2u);
  EXPECT_EQ(r.lanes[0].id, 1);
  EXPECT_EQ(r.lanes[0].subtype, LaneSubtype::kRoad);
  EXPECT_EQ(r.lanes[1].id, 2);
  EXPECT_EQ(r.lanes[1].subtype, LaneSubtype::kRoadShoulder);
  ASSERT_EQ(r.lanes[1].left_bound.size(), 2u);
  EXPECT_DOUBLE_EQ(r.lanes[1].left_bound[0].y, 4.75);
  EXPECT_DOUBLE_EQ(r.lanes[1].right_bound[1].x, 100.0);
  EXPECT_GT(r.lanes[0].speed_limit_mps, 0.0);
  EXPECT_DOUBLE_EQ(r.ego_pose.x, 10.0);
  EXPECT_DOUBLE_EQ(r.ego_pose.y, 3.25);
  EXPECT_DOUBLE_EQ(r.ego_pose.yaw, 0.0);
  EXPECT_DOUBLE_EQ(r.goal_pose.x, 90.0);
  EXPECT_TRUE(r.objects.empty());
  ASSERT_TRUE(s.expect.found.has_value());
  EXPECT_TRUE(*s.expect.found);
  EXPECT_EQ(s.expect.planner, PlannerType::kShift);
}

TEST(Scenario, EveryScenarioInTheSuiteLoads) {
  std::size_t count = 0;
  for (const auto& entry : std::filesystem::directory_iterator(kScenarioDir)) {
    if (entry.path().extension() != ".yaml") continue;
    ++count;
    try {
      const Scenario s = load_scenario(entry.path().string());
      // Inline lanes, a route on the scenario's map, or a grid for a pure freespace problem.
      EXPECT_TRUE(!s.request.lanes.empty() || (s.map && has_route(s.request)) || s.request.occupancy_grid.has_value())
          << entry.path();
    } catch (const ConfigError& e) {
      ADD_FAILURE() << e.what();
    }
  }
  EXPECT_GE(count, 1u);
}

TEST(Scenario, AllFieldsAndOverrides) {
  ScenarioFile file(std::string(kLanes) +
                    "description: everything\n"
                    "vehicle_id: demo-1\n"
                    "vehicle: {wheel_base: 3.0}\n"
                    "start: {x: 10.0, y: 3.5, yaw: 0.1}\n"
                    "start_velocity: 0.2\n"
                    "goal: {x: 90.0, y: 0.0, yaw_deg: 90}\n"
                    "objects:\n"
                    "  - {id: 7, class: car, x: 20.0, y: 3.5, yaw_deg: 180, length: 4.0, width: 1.8, velocity: 0.5}\n"
                    "  - {class: pedestrian, x: 30, y: 4, polygon: [[-0.3, -0.3], [0.3, -0.3], [0, 0.3]]}\n"
                    "planner: {search_priority: [SHIFT], lateral_jerk: 0.7}\n"
                    "deadline_ms: 150\n"
                    "expect: {found: false, margin: 0.5}\n");
  Config base;
  base.vehicle.wheel_tread_m = 1.7;
  const Scenario s = load_scenario(file.path(), base);
  EXPECT_EQ(s.request.vehicle_id, "demo-1");
  EXPECT_DOUBLE_EQ(s.vehicle.wheel_base_m, 3.0);
  EXPECT_DOUBLE_EQ(s.vehicle.wheel_tread_m, 1.7);  // from the base config
  EXPECT_DOUBLE_EQ(s.request.ego_pose.yaw, 0.1);
  EXPECT_DOUBLE_EQ(s.request.ego_velocity_mps, 0.2);
  EXPECT_NEAR(s.request.goal_pose.yaw, kPi / 2.0, 1e-12);
  ASSERT_EQ(s.request.objects.size(), 2u);
  EXPECT_EQ(s.request.objects[0].id, 7);
  EXPECT_EQ(s.request.objects[0].object_class, ObjectClass::kCar);
  EXPECT_NEAR(s.request.objects[0].pose.yaw, kPi, 1e-12);
  EXPECT_DOUBLE_EQ(s.request.objects[0].length_m, 4.0);
  EXPECT_DOUBLE_EQ(s.request.objects[0].velocity_mps, 0.5);
  EXPECT_EQ(s.request.objects[1].object_class, ObjectClass::kPedestrian);
  EXPECT_EQ(s.request.objects[1].polygon.size(), 3u);
  EXPECT_DOUBLE_EQ(s.parameters.lateral_jerk, 0.7);
  EXPECT_EQ(s.request.overrides.search_priority, std::vector<PlannerType>{PlannerType::kShift});
  EXPECT_FALSE(s.request.overrides.search_policy.has_value());
  EXPECT_DOUBLE_EQ(s.request.deadline_ms, 150.0);
  EXPECT_EQ(s.expect.found, false);
  EXPECT_EQ(s.expect.margin_m, 0.5);
}

// A request carries only search_priority and search_policy; every other `planner:` key is named
// (dotted, in file order) so that `pullout request` can say the service will not use it.
TEST(Scenario, PlannerKeysARequestDoesNotCarryAreListed) {
  ScenarioFile file(std::string(kLanes) +
                    "start: {x: 10.0, y: 3.5, yaw: 0.0}\ngoal: {x: 90.0, y: 0.0, yaw: 0.0}\n"
                    "planner:\n  lateral_jerk: 0.7\n  search_priority: [SHIFT]\n"
                    "  freespace_planner: {vehicle_shape_margin: 0.4, astar: {distance_heuristic_weight: 1.5}}\n"
                    "  search_policy: distance_priority\n");
  const Scenario s = load_scenario(file.path());
  EXPECT_EQ(s.local_planner_keys, (std::vector<std::string>{"lateral_jerk", "freespace_planner.vehicle_shape_margin",
                                                            "freespace_planner.astar.distance_heuristic_weight"}));
  EXPECT_EQ(s.request.overrides.search_priority, std::vector<PlannerType>{PlannerType::kShift});

  ScenarioFile carried(std::string(kLanes) +
                       "start: {x: 10.0, y: 3.5, yaw: 0.0}\ngoal: {x: 90.0, y: 0.0, yaw: 0.0}\n"
                       "planner: {search_priority: [SHIFT], search_policy: distance_priority}\n");
  EXPECT_TRUE(load_scenario(carried.path()).local_planner_keys.empty());
}

// Headings are read into [-pi, pi], as a request's quaternion carries them: 1e10 degrees was
// planned and echoed as 174532925 rad.
TEST(Scenario, HeadingsAreNormalised) {
  ScenarioFile file(std::string(kLanes) + "start: {x: 10.0, y: 3.5, yaw_deg: 370}\n" +
                    "goal: {x: 90.0, y: 0.0, yaw: -7.0}\n" +
                    "objects:\n  - {id: 7, class: car, x: 20.0, y: 3.5, yaw_deg: 1e10, length: 4.0, width: 1.8}\n");
  const Scenario s = load_scenario(file.path());
  EXPECT_NEAR(s.request.ego_pose.yaw, 10.0 * kDegToRad, 1e-12);
  EXPECT_NEAR(s.request.goal_pose.yaw, -7.0 + 2.0 * kPi, 1e-12);
  const double object_yaw = s.request.objects.at(0).pose.yaw;
  EXPECT_GE(object_yaw, -kPi);
  EXPECT_LE(object_yaw, kPi);
  EXPECT_NEAR(std::remainder(object_yaw - 1e10 * kDegToRad, 2.0 * kPi), 0.0, 1e-6);
}

TEST(Scenario, VehicleIdDefaultsToTheFileName) {
  ScenarioFile file(std::string(kLanes) + kPoses);
  const Scenario s = load_scenario(file.path());
  EXPECT_EQ(s.request.vehicle_id, std::filesystem::path(file.path()).stem().string());
}

TEST(Scenario, MalformedPointsAreNamed) {
  const auto p = problems_of(
      std::string(kPoses) +
      "lanes:\n"
      "  - {id: 1, left_bound: [[0, 1.75], [50, 1.75], [100], [100, 1.75]], right_bound: [[0, -1.75], [100, x]]}\n");
  EXPECT_TRUE(any_starts_with(p, "lanes[0].left_bound[2]: expected [x, y]")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "lanes[0].right_bound[1].y: expected a number")) << dump(p);
  EXPECT_EQ(p.size(), 2u) << dump(p);
}

TEST(Scenario, MalformedFieldsAreNamed) {
  const auto p = problems_of(std::string(kLanes) +
                             "start: {x: 10, y: ten, yaw: 0, yaw_deg: 0}\n"
                             "goal: {x: 90}\n"
                             "objects:\n"
                             "  - {id: 1, class: spaceship, x: 1, y: 2, length: -4}\n"
                             "  - {id: 2, class: car, x: 1, y: 2, colour: red}\n"
                             "planner: {lateral_jerk: fast}\n"
                             "expect: {planner: teleport}\n"
                             "deadline_ms: -1\n");
  EXPECT_TRUE(any_starts_with(p, "start.y: expected a number, got 'ten'")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "start.yaw_deg: give either yaw [rad] or yaw_deg, not both")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "goal.y: required")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "objects[0].class: unknown class 'spaceship'")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "objects[0].length: must be > 0")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "objects[1].colour: unknown key")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "planner.lateral_jerk: expected a number")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "expect.planner: unknown planner 'teleport'")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "deadline_ms: must be >= 0")) << dump(p);
  EXPECT_EQ(p.size(), 9u) << dump(p);
}

TEST(Scenario, MissingRequiredParts) {
  const auto p = problems_of("objects: []\n");
  EXPECT_TRUE(any_starts_with(p, "lanes: required")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "start: required")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "goal: required")) << dump(p);

  const auto q = problems_of(std::string(kPoses) + "lanes:\n  - {id: 3, left_bound: [[0, 1]]}\n");
  EXPECT_TRUE(any_starts_with(q, "lanes[0].left_bound: needs at least 2 points")) << dump(q);
  EXPECT_TRUE(any_starts_with(q, "lanes[0].right_bound: required")) << dump(q);
}

TEST(Scenario, MapAndRouteLoadTheMap) {
  const Scenario sc = load_scenario(kScenarioDir + "/map_shoulder.yaml");
  ASSERT_TRUE(sc.map);
  EXPECT_EQ(sc.map_path, std::filesystem::path(std::string(PULLOUT_SOURCE_DIR) + "/tests/maps/straight_shoulder.osm")
                             .lexically_normal()
                             .string());
  EXPECT_EQ(sc.request.route_lanelet_ids, (std::vector<std::int64_t>{101, 102, 103}));
  EXPECT_TRUE(sc.request.lanes.empty());
  EXPECT_EQ(sc.map->lanelets().size(), 7u);
}

TEST(Scenario, MapAndRouteProblems) {
  auto p = problems_of(std::string(kPoses) + "map: /nonexistent/map.osm\nroute: [4618, 4635]\n");
  EXPECT_TRUE(any_starts_with(p, "map: /nonexistent/map.osm: cannot read file")) << dump(p);
  const std::string own_map = std::string(PULLOUT_SOURCE_DIR) + "/tests/maps/straight_shoulder.osm";
  p = problems_of(std::string(kPoses) + "map: " + own_map + "\n");
  EXPECT_TRUE(any_starts_with(p, "route: required with map:")) << dump(p);
  p = problems_of(std::string(kPoses) + "map: " + own_map + "\nroute: [101, x]\n");
  EXPECT_TRUE(any_starts_with(p, "route[1]: expected")) << dump(p);
  p = problems_of(std::string(kPoses) + kLanes + "route: [101]\n");
  EXPECT_TRUE(any_starts_with(p, "lanes: give either inline lanes or a route")) << dump(p);
  // A malformed map file: the scenario names it.
  const std::string broken_map =
      (std::filesystem::temp_directory_path() / ("pullout_broken_map_" + std::to_string(::getpid()) + ".osm")).string();
  std::ofstream(broken_map) << "<osm><node id=\"1\"></osm>\n";
  p = problems_of(std::string(kPoses) + "map: " + broken_map + "\nroute: [1]\n");
  std::filesystem::remove(broken_map);
  EXPECT_TRUE(any_starts_with(p, "map: " + broken_map + ": line 1: not valid XML")) << dump(p);
  // A route without a map is for a service that has the map.
  p = problems_of(std::string(kPoses) + "route: [101, 102]\n");
  EXPECT_TRUE(p.empty()) << dump(p);
}

// route: as Autoware route segments, {preferred, primitives}.
TEST(Scenario, RouteAsSegments) {
  const Scenario sc = load_scenario(kScenarioDir + "/map_lane_change_route.yaml");
  ASSERT_TRUE(sc.map);
  EXPECT_TRUE(sc.request.route_lanelet_ids.empty());
  ASSERT_EQ(sc.request.route_segments.size(), 3u);
  EXPECT_EQ(sc.request.route_segments[1].preferred_id, 122);
  EXPECT_EQ(sc.request.route_segments[1].primitive_ids, (std::vector<std::int64_t>{112, 122}));
  const std::string own_map = std::string(PULLOUT_SOURCE_DIR) + "/tests/maps/two_lane_road.osm";
  auto p = problems_of(std::string(kPoses) + "map: " + own_map + "\nroute: [{preferred: 111}, {primitives: [112]}]\n");
  EXPECT_TRUE(any_starts_with(p, "route[1].preferred: required")) << dump(p);
  p = problems_of(std::string(kPoses) + "map: " + own_map + "\nroute: [{preferred: 111, primitives: [111, y]}]\n");
  EXPECT_TRUE(any_starts_with(p, "route[0].primitives[1]: expected")) << dump(p);
  p = problems_of(std::string(kPoses) + "map: " + own_map + "\nroute: [{preferred: 111, lanes: [1]}]\n");
  EXPECT_TRUE(any_starts_with(p, "route[0].lanes: unknown key")) << dump(p);
  p = problems_of(std::string(kPoses) + "map: " + own_map + "\nroute: [{preferred: 111}, 112]\n");
  EXPECT_FALSE(p.empty());
  p = problems_of(std::string(kPoses) + "map: " + own_map + "\nroute: [111, {preferred: 112}]\n");
  EXPECT_TRUE(any_starts_with(p, "route[1]: expected a lanelet id")) << dump(p);
}

TEST(Scenario, PlannerSectionIsValidated) {
  const auto p = problems_of(std::string(kLanes) + kPoses +
                             "planner: {search_priority: [SHIFT, SHIFT], lateral_jerk: 0}\nvehicle: {wheel_base: 0}\n");
  EXPECT_TRUE(any_starts_with(p, "planner.search_priority[1]: planner 'shift' is listed twice")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "planner.lateral_jerk: must be > 0")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "vehicle.wheel_base: must be in")) << dump(p);
}

TEST(Scenario, GridFromObstacleShapes) {
  ScenarioFile file(std::string(kPoses) +
                    "grid:\n  resolution: 0.5\n  origin: {x: -1.0, y: -2.0}\n  size: [10, 5]\n"
                    "  obstacles:\n    - {x: 2.0, y: 0.0, length: 1.0, width: 1.0}\n"
                    "    - {polygon: [[6.1, -1.9], [7.9, -1.9], [7.9, -1.1]]}\n");
  const Scenario s = load_scenario(file.path());
  ASSERT_TRUE(s.request.occupancy_grid.has_value());
  const OccupancyGrid& g = *s.request.occupancy_grid;
  EXPECT_EQ(g.width, 20u);
  EXPECT_EQ(g.height, 10u);
  EXPECT_DOUBLE_EQ(g.origin.x, -1.0);
  const auto at = [&](double x, double y) {
    return g.data[static_cast<std::size_t>((y + 2.0) / 0.5) * g.width + static_cast<std::size_t>((x + 1.0) / 0.5)];
  };
  EXPECT_EQ(at(2.0, 0.0), 100);   // inside the box [1.5, 2.5] x [-0.5, 0.5]
  EXPECT_EQ(at(1.4, 0.0), 0);     // the cell [1.0, 1.5] touches it only at x = 1.5
  EXPECT_EQ(at(7.0, -1.6), 100);  // the triangle
  EXPECT_EQ(at(5.0, 2.0), 0);
  EXPECT_TRUE(s.request.lanes.empty());
}

TEST(Scenario, GridObstacleOutsideTheGridIsAnError) {
  // A typo or wrong units would otherwise be dropped silently, leaving a free grid and a path
  // (1e300 is beyond the coordinate limit: GridObstacleCoordinatesAreBounded).
  const auto p = problems_of(std::string(kPoses) +
                             "grid:\n  resolution: 0.5\n  origin: {x: -1.0, y: -2.0}\n  size: [10, 5]\n"
                             "  obstacles:\n    - {x: 1e6, y: 0.0, length: 1.0, width: 1.0}\n"
                             "    - {x: 2.0, y: 0.0, length: 1.0, width: 1.0}\n"
                             "    - {polygon: [[20, 0], [21, 0], [21, 1]]}\n"
                             "    - {x: 9.4, y: 3.4, length: 1.0, width: 1.0}\n");
  EXPECT_TRUE(any_starts_with(p, "grid.obstacles[0] (at x 1e+06, y 0): lies entirely outside the grid")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "grid.obstacles[2].polygon: lies entirely outside the grid")) << dump(p);
  EXPECT_EQ(p.size(), 2u) << dump(p);  // [1] inside, [3] reaches in from the far corner
}

TEST(Scenario, GridSizeOfAnyMagnitudeIsChecked) {
  for (const char* size : {"[1e300, 5]", "[10, -1e300]", "[1e-300, 5]"}) {
    const auto p = problems_of(std::string(kPoses) + "grid:\n  resolution: 0.5\n  size: " + size + "\n");
    EXPECT_TRUE(any_starts_with(p, "grid.size: must give 1 to")) << size << ": " << dump(p);
  }
  // No obstacles and no size at all: a problem, not an exception.
  const auto p = problems_of(std::string(kPoses) + "grid:\n  resolution: 0.5\n");
  EXPECT_TRUE(any_starts_with(p, "grid.size: required")) << dump(p);
}

TEST(Scenario, GridCellSizeIsBounded) {
  for (const char* resolution : {"1e-308", "0", "-0.5", "5.5"}) {
    const auto p = problems_of(std::string(kPoses) + "grid:\n  resolution: " + resolution + "\n  size: [10, 5]\n");
    EXPECT_TRUE(any_starts_with(p, "grid.resolution: within [0.01, 5] [m]")) << resolution << ": " << dump(p);
  }
  EXPECT_TRUE(problems_of(std::string(kPoses) + "grid:\n  resolution: 0.01\n  size: [10, 5]\n").empty());
}

TEST(Scenario, GridFromAMapServerImage) {
  // A 4 x 3 P2 image: black (occupied), white (free), grey (unknown); the top row first.
  const auto dir = std::filesystem::temp_directory_path() / ("pullout_test_map_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "lot.pgm") << "P2\n# a comment\n4 3\n255\n0 255 255 255\n255 128 255 255\n255 255 255 0\n";
  std::ofstream(dir / "lot.yaml") << "image: lot.pgm\nresolution: 0.5\norigin: [1.0, 2.0, 0.0]\n"
                                     "occupied_thresh: 0.65\nfree_thresh: 0.196\nnegate: 0\n";
  std::ofstream(dir / "scenario.yaml") << kPoses << "grid: {map: lot.yaml}\n";
  const Scenario s = load_scenario((dir / "scenario.yaml").string());
  ASSERT_TRUE(s.request.occupancy_grid.has_value());
  const OccupancyGrid& g = *s.request.occupancy_grid;
  EXPECT_EQ(g.width, 4u);
  EXPECT_EQ(g.height, 3u);
  EXPECT_DOUBLE_EQ(g.origin.y, 2.0);
  // Grid row 0 is the image's bottom row.
  EXPECT_EQ(g.data[0 * 4 + 3], 100);
  EXPECT_EQ(g.data[0 * 4 + 0], 0);
  EXPECT_EQ(g.data[1 * 4 + 1], -1);
  EXPECT_EQ(g.data[2 * 4 + 0], 100);

  // P5 (binary) gives the same grid.
  std::ofstream(dir / "lot.pgm", std::ios::binary)
      << "P5\n4 3\n255\n"
      << std::string("\x00\xff\xff\xff\xff\x80\xff\xff\xff\xff\xff\x00", 12);
  const Scenario b = load_scenario((dir / "scenario.yaml").string());
  EXPECT_EQ(b.request.occupancy_grid->data, g.data);

  std::ofstream(dir / "lot.yaml") << "image: missing.pgm\nresolution: 0.5\norigin: [1.0, 2.0]\n";
  const auto p = problems_of_file((dir / "scenario.yaml").string());
  EXPECT_TRUE(any_starts_with(p, "grid.map.origin: required")) << dump(p);
  std::filesystem::remove_all(dir);
}

TEST(Scenario, GridFilesThatAreDirectoriesAreProblems) {
  // `grid: {map: }` names the scenario's own directory, and an image may name a directory too:
  // reading one threw std::ios_failure out of load_scenario (found by fuzz_scenario).
  const auto dir = std::filesystem::temp_directory_path() / ("pullout_test_dir_map_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir / "images");
  std::ofstream(dir / "scenario.yaml") << kPoses << "grid: {map: }\n";
  auto p = problems_of_file((dir / "scenario.yaml").string());
  EXPECT_TRUE(any_starts_with(p, "grid.map: ")) << dump(p);

  std::ofstream(dir / "lot.yaml") << "image: images\nresolution: 0.5\norigin: [1.0, 2.0, 0.0]\n";
  std::ofstream(dir / "scenario.yaml") << kPoses << "grid: {map: lot.yaml}\n";
  p = problems_of_file((dir / "scenario.yaml").string());
  EXPECT_TRUE(any_starts_with(p, (dir / "images").string() + ": cannot read file")) << dump(p);
  std::filesystem::remove_all(dir);
}

// A scenario's grid is bounded by the request limit the planner applies (service.limits.
// max_grid_cells): the loader allowed 4 times as many cells, so an 8192 x 8192 grid cost 1.1 s
// and 230 MB to build, then was rejected by the planner, or (pullout request) sent as a 64 MB
// sample the service drops unanswered.
TEST(Scenario, GridCellsAreBoundedByTheRequestLimit) {
  auto p = problems_of(std::string(kPoses) + "grid:\n  resolution: 0.01\n  size: [40.97, 40.96]\n");
  EXPECT_TRUE(any_starts_with(p,
                              "grid.size: must give 1 to 16777216 cells (service.limits.max_grid_cells), got "
                              "4097 x 4096 = 16781312"))
      << dump(p);

  Config base;
  base.service.limits.max_grid_cells = 100;
  ScenarioFile file(std::string(kPoses) + "grid:\n  resolution: 0.5\n  size: [10, 5]\n");
  try {
    load_scenario(file.path(), base);
    ADD_FAILURE() << "200 cells over a limit of 100 loaded";
  } catch (const ConfigError& e) {
    EXPECT_TRUE(any_starts_with(e.problems(), "grid.size: must give 1 to 100 cells")) << dump(e.problems());
  }

  // A map_server image is checked against the limit from its header, before its pixels are read.
  const auto dir = std::filesystem::temp_directory_path() / ("pullout_test_big_map_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "lot.pgm", std::ios::binary) << "P5\n20 10\n255\n" << std::string(200, '\xff');
  std::ofstream(dir / "lot.yaml") << "image: lot.pgm\nresolution: 0.5\norigin: [0.0, 0.0, 0.0]\n";
  std::ofstream(dir / "scenario.yaml") << kPoses << "grid: {map: lot.yaml}\n";
  try {
    load_scenario((dir / "scenario.yaml").string(), base);
    ADD_FAILURE() << "a 20 x 10 image over a limit of 100 cells loaded";
  } catch (const ConfigError& e) {
    EXPECT_TRUE(any_starts_with(e.problems(), (dir / "lot.pgm").string() +
                                                  ": 20 x 10 pixels exceed the limit of 100 cells "
                                                  "(service.limits.max_grid_cells)"))
        << dump(e.problems());
  }
  std::filesystem::remove_all(dir);
}

// Obstacle shapes are bounded like every coordinate of a request (service.limits.max_coordinate_m):
// a box 1e100 m long lost its position and width to rounding (its corners 8.7e93 m out) and was
// drawn along the grid's bottom row instead of across its middle, and corners of 1.7e308 m
// overflowed to infinity in the grid frame and drew nothing: both gave a path through the wall.
TEST(Scenario, GridObstacleCoordinatesAreBounded) {
  const std::string grid = std::string(kPoses) + "grid:\n  resolution: 0.2\n  size: [30, 30]\n  obstacles:\n";
  auto p = problems_of(grid +
                       "    - {x: 15, y: 15, yaw_deg: 0.0001, length: 1e100, width: 2}\n"
                       "    - {polygon: [[-1.7e308, 14], [1.7e308, 14], [1.7e308, 16], [-1.7e308, 16]]}\n"
                       "    - {x: 15, y: -2e7, length: 1, width: 3e7}\n");
  EXPECT_TRUE(any_starts_with(p, "grid.obstacles[0].length: 1e+100 exceeds 1e+07 m")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "grid.obstacles[1].polygon[0].x: |x| 1.7e+308 exceeds 1e+07 m")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "grid.obstacles[2].y: |y| 2e+07 exceeds 1e+07 m")) << dump(p);
  EXPECT_TRUE(any_starts_with(p, "grid.obstacles[2].width: 3e+07 exceeds 1e+07 m")) << dump(p);

  // At the limit the wall stays where it is: across the middle of the grid.
  ScenarioFile file(grid + "    - {x: 15, y: 15, yaw_deg: 0.0001, length: 1e7, width: 2}\n");
  const Scenario s = load_scenario(file.path());
  const OccupancyGrid& g = *s.request.occupancy_grid;
  EXPECT_EQ(g.data[static_cast<std::size_t>(15.0 / 0.2) * g.width + 10], 100);  // x 2, y 15
  EXPECT_EQ(g.data[static_cast<std::size_t>(5.0 / 0.2) * g.width + 10], 0);     // x 2, y 5
  EXPECT_EQ(g.data[10], 0);                                                     // x 2, y 0.1
}

// As many obstacle shapes and polygon points as a request's objects may have: drawing costs each
// shape's area in cells (50,000 boxes took over a minute and 2.4 GB, one polygon of 20,000 points
// 8 s), so more are refused before any is drawn, naming the limit.
TEST(Scenario, GridObstacleCountsAreBoundedAsARequestsObjects) {
  const std::string grid = std::string(kPoses) + "grid:\n  resolution: 0.2\n  size: [30, 30]\n  obstacles:\n";
  std::string many;
  for (int i = 0; i < 513; ++i) many += "    - {x: 15, y: 15, length: 1, width: 1}\n";
  auto p = problems_of(grid + many);
  EXPECT_TRUE(any_starts_with(p, "grid.obstacles: 513 shapes exceed the limit of 512 (service.limits.max_objects)"))
      << dump(p);
  std::string points = "    - {polygon: [";
  for (int k = 0; k < 65; ++k)
    points += (k > 0 ? ", [" : "[") + std::to_string(15.0 + std::cos(k * 0.0966)) + ", " +
              std::to_string(15.0 + std::sin(k * 0.0966)) + "]";
  p = problems_of(grid + points + "]}\n");
  EXPECT_TRUE(any_starts_with(p,
                              "grid.obstacles[0].polygon: 65 points exceed the limit of 64 "
                              "(service.limits.max_polygon_points)"))
      << dump(p);
  // At the limits: loaded.
  many.resize(many.size() / 513 * 512);
  EXPECT_TRUE(problems_of(grid + many).empty());
}

// Within those limits drawing can still cost the shapes' area: 512 polygons zigzagging across a
// grid of 16 Mi cells took 29 s and 640 MB. Past 2 s of drawing the file is refused, saying why.
TEST(Scenario, DrawingAGridsObstaclesIsBoundedInTime) {
  std::string text = std::string(kPoses) + "grid:\n  resolution: 0.01\n  size: [40.96, 40.96]\n  obstacles:\n";
  for (int j = 0; j < 512; ++j) {
    text += "    - {polygon: [";
    for (int k = 0; k < 64; ++k) {
      text += (k > 0 ? ", [" : "[") + std::to_string(k % 2 == 0 ? 0.0 : 40.96) + ", " +
              std::to_string(0.64 * k + 0.001 * j) + "]";
    }
    text += "]}\n";
  }
  const auto p = problems_of(text);
  EXPECT_TRUE(any_starts_with(p, "grid.obstacles: drawing them on 4096 x 4096 cells took longer than 2 s")) << dump(p);
}

// The image of a map_server grid is read no further than its header says: the whole file was read
// into memory first, so that an image path naming a 2 GB file cost 20 s and 4 GB (6 GB when it
// was no image at all). A FIFO blocked the loader for good (opened before it was checked), and a
// file that fails to read (/proc/self/mem) threw std::ios_failure out of load_scenario.
TEST(Scenario, GridImageCostsNoMoreThanItsHeaderDeclares) {
  const auto dir = std::filesystem::temp_directory_path() / ("pullout_test_image_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "scenario.yaml") << kPoses << "grid: {map: lot.yaml}\n";
  const auto image = [&](const std::string& file) {
    std::ofstream(dir / "lot.yaml") << "image: " << file << "\nresolution: 0.5\norigin: [0.0, 0.0, 0.0]\n";
  };
  const auto scenario = (dir / "scenario.yaml").string();

  // 4 x 3 pixels, then 512 MiB of nothing (sparse): the image loads, and the rest is not read.
  std::ofstream(dir / "lot.pgm", std::ios::binary) << "P5\n4 3\n255\n" << std::string(12, '\xff');
  std::filesystem::resize_file(dir / "lot.pgm", std::uintmax_t{512} << 20);
  image("lot.pgm");
  const Scenario s = load_scenario(scenario);
  EXPECT_EQ(s.request.occupancy_grid->data, std::vector<std::int8_t>(12, 0));
  // What that load adds to the peak memory, in a child of its own: its peak starts at what it
  // has resident when forked (this process's own peak includes whatever ran before in it).
  int pipe_fds[2] = {-1, -1};
  ASSERT_EQ(::pipe(pipe_fds), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    rusage before{};
    rusage after{};
    ::getrusage(RUSAGE_SELF, &before);
    const Scenario again = load_scenario(scenario);
    ::getrusage(RUSAGE_SELF, &after);
    const long grown = again.request.occupancy_grid ? after.ru_maxrss - before.ru_maxrss : -1;
    const ssize_t written = ::write(pipe_fds[1], &grown, sizeof grown);
    ::_exit(written == static_cast<ssize_t>(sizeof grown) ? 0 : 1);
  }
  ::close(pipe_fds[1]);
  long grown = -1;
  const ssize_t got = ::read(pipe_fds[0], &grown, sizeof grown);
  ::close(pipe_fds[0]);
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  ASSERT_EQ(got, static_cast<ssize_t>(sizeof grown));
  EXPECT_GE(grown, 0);
  EXPECT_LT(grown, 256L * 1024) << "peak resident set added by the load [KiB]";

  // A header declaring more than the file holds is found before the pixels are allocated.
  std::ofstream(dir / "lot.pgm", std::ios::binary | std::ios::trunc) << "P5\n4000 4000\n65535\n"
                                                                     << std::string(10, 'x');
  auto p = problems_of_file(scenario);
  EXPECT_TRUE(any_starts_with(
      p, (dir / "lot.pgm").string() + ": truncated PGM data: 4000 x 4000 pixels need 32000000 bytes, the file has 10"))
      << dump(p);

  ASSERT_EQ(::mkfifo((dir / "fifo.pgm").c_str(), 0600), 0);
  image("fifo.pgm");
  p = problems_of_file(scenario);
  EXPECT_TRUE(any_starts_with(p, (dir / "fifo.pgm").string() + ": cannot read file (not a regular file)")) << dump(p);

  if (std::filesystem::exists("/proc/self/mem")) {
    image("/proc/self/mem");
    p = problems_of_file(scenario);
    EXPECT_TRUE(any_starts_with(p, "/proc/self/mem: not a PGM image")) << dump(p);
    std::ofstream(dir / "scenario.yaml") << kPoses << "grid: {map: /proc/self/mem}\n";
    p = problems_of_file(scenario);
    EXPECT_TRUE(any_starts_with(p, "grid.map: /proc/self/mem: cannot read file")) << dump(p);
  }
  std::filesystem::remove_all(dir);
}

TEST(Scenario, UnreadableFile) {
  try {
    load_scenario("/nonexistent/scenario.yaml");
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), "/nonexistent/scenario.yaml: cannot read file");
  }
}

}  // namespace
}  // namespace pullout

namespace pullout {
namespace {

TEST(ScenarioVehicle, AProfileIsNamedInTheRequestAndDimensionsAreCarried) {
  ScenarioFile profile(std::string(kLanes) + kPoses + "vehicle: {profile: bus}\n");
  const Scenario bus = load_scenario(profile.path());
  EXPECT_EQ(bus.request.vehicle_profile, "bus");
  EXPECT_FALSE(bus.request.vehicle);
  EXPECT_NEAR(bus.vehicle.length_m(), 12.0, 1e-9);  // the config's bus, for the CLI's drawing

  ScenarioFile own(std::string(kLanes) + kPoses + "vehicle: {wheel_base: 3.5}\n");
  const Scenario van = load_scenario(own.path());
  ASSERT_TRUE(van.request.vehicle);
  EXPECT_DOUBLE_EQ(van.request.vehicle->wheel_base_m, 3.5);
  EXPECT_TRUE(van.request.vehicle_profile.empty());

  // Both at once is ambiguous; an unknown profile is the planner's to reject (the service has its own).
  const auto both = problems_of(std::string(kLanes) + kPoses + "vehicle: {profile: bus, wheel_base: 3}\n");
  ASSERT_EQ(both.size(), 1u);
  EXPECT_NE(both[0].find("vehicle.profile"), std::string::npos) << both[0];
  EXPECT_TRUE(problems_of(std::string(kLanes) + kPoses + "vehicle: {profile: tram}\n").empty());
}

TEST(ScenarioFleet, TheOtherVehiclesShareTheWorldWithTheirOwnPosesAndVehicles) {
  const Scenario sc = load_scenario(kScenarioDir + "/fleet_opposite_shoulders.yaml");
  ASSERT_EQ(sc.fleet.size(), 1u);
  EXPECT_EQ(sc.fleet[0].vehicle_id, "fleet-a");
  EXPECT_EQ(sc.fleet[0].lanes.size(), sc.request.lanes.size());
  EXPECT_DOUBLE_EQ(sc.fleet[0].ego_pose.y, 3.25);
  EXPECT_EQ(sc.expect.waits_for, std::optional<std::string>("fleet-a"));

  const auto p = problems_of(std::string(kLanes) + kPoses +
                             "vehicle_id: me\nfleet:\n  - {vehicle_id: me, start: {x: 1, y: 0}, goal: {x: 9, y: 0}}\n"
                             "  - {start: {x: 1, y: 0}, goal: {x: 9, y: 0}, colour: red, vehicle: {profile: 3}}\n");
  std::string all;
  for (const auto& line : p) all += line + "\n";
  EXPECT_NE(all.find("fleet[0].vehicle_id: 'me' is this scenario's own vehicle"), std::string::npos) << all;
  EXPECT_NE(all.find("fleet[1].vehicle_id: required"), std::string::npos) << all;
  EXPECT_NE(all.find("fleet[1].colour"), std::string::npos) << all;
}

}  // namespace
}  // namespace pullout
