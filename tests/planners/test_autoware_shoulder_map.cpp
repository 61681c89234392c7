// Pull-out from every road_shoulder lanelet of Autoware's own start-planner test map
// (../shared/maps/autoware_road_shoulder: 371 lanelets, 95 shoulders, curved roads, left-hand
// traffic with the shoulders on the left), as Autoware's start-planner tests do: the vehicle on the
// shoulder's centerline, the route along the road beside it, the start yaw along the lane and
// +-10 degrees off it; each planner alone, from the current pose (no backward search), and the
// shift planner must give 1 segment, the geometric planner (divide_pull_out_path) 2. Every path
// found is checked by the independent oracles (inside the map's lanelets, curvature within the
// vehicle's limit). The map is read at run time; the test skips, naming the path, when it is absent.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include "map_cases.hpp"
#include "path_oracles.hpp"
#include "pullout/collision/footprint.hpp"
#include "pullout/config/config.hpp"
#include "pullout/geometry/angle.hpp"
#include "pullout/lanes/lane_world.hpp"
#include "pullout/maps/lanelet_map.hpp"
#include "pullout/maps/osm_loader.hpp"
#include "pullout/model/names.hpp"
#include "pullout/pipeline/start_planner.hpp"

namespace pullout {
namespace {

using namespace oracle;  // NOLINT: the test's own helpers

const std::string kMap = std::string(PULLOUT_SOURCE_DIR) + "/../shared/maps/autoware_road_shoulder/lanelet2_map.osm";

struct Verdict {
  bool passed{false};
  std::string why;  // when not passed
};

// The path is inside the map's road and shoulder lanelets (expanded footprint as the planner's
// own lane check) and turns no tighter than the vehicle can, up to the end pose.
std::string oracle_problem(const PullOutPath& path, const std::vector<Polygon>& lanes, const VehicleInfo& vehicle,
                           const StartPlannerParameters& params) {
  const double expansion = path.planner_type == PlannerType::kGeometric ? params.lane_departure_margin
                                                                        : params.lane_departure_check_expansion_margin;
  const Footprint fp = vehicle_footprint(vehicle, expansion);
  const double k_max = 1.0 / vehicle.min_turning_radius_m();
  for (std::size_t k = 0; k < path.partial_paths.size(); ++k) {
    const auto& points = path.partial_paths[k].points;
    if (points.size() < 2) return "segment " + std::to_string(k) + " has fewer than 2 points";
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Pose2& pose = points[i].pose;
      if (!footprint_in_lanes(fp, pose, lanes)) {
        return "oracle: lane departure at segment " + std::to_string(k) + " point " + std::to_string(i);
      }
      if (i > 0 && i + 1 < points.size()) {
        const double kappa =
            menger_curvature(to_vec(points[i - 1].pose), to_vec(pose), to_vec(points[i + 1].pose));
        if (std::abs(kappa) > k_max * 1.02) return "oracle: curvature at segment " + std::to_string(k);
      }
      if (k + 1 == path.partial_paths.size() &&
          std::hypot(pose.x - path.end_pose.x, pose.y - path.end_pose.y) < 1e-6) {
        return "";  // beyond the end pose the path runs on along the road's centerline
      }
    }
  }
  return "";
}

Verdict plan_one(const LaneletMap& map, const std::shared_ptr<const LaneletMap>& shared, const Config& config,
                 PlannerType planner_type, const ShoulderCase& c, double yaw_offset,
                 const std::vector<Polygon>& lanes) {
  StartPlannerParameters params = config.start_planner;
  params.search_priority = {planner_type};
  params.enable_back = false;  // from the current pose, as Autoware's planner tests
  params.freespace_planner.enable_freespace_planner = false;
  params.divide_pull_out_path = true;
  const StartPlanner planner(config.vehicle, params, config.service.limits, shared);
  PullOutRequest r;
  r.vehicle_id = "shoulder-map";
  r.request_id = 1;
  r.route_lanelet_ids = c.route;
  r.ego_pose = c.ego;
  r.ego_pose.yaw = normalize_angle(c.ego.yaw + yaw_offset);
  r.goal_pose = c.goal;
  const PlanningResult result = planner.plan(r, StopCondition());
  Verdict v;
  if (result.outcome != PlanningResult::Outcome::kFound) {
    v.why = result.outcome == PlanningResult::Outcome::kRejected ? format_issues(result.issues) : result.stop_reason;
    return v;
  }
  const std::size_t expected = planner_type == PlannerType::kShift ? 1 : 2;
  if (result.path.partial_paths.size() != expected) {
    v.why = std::to_string(result.path.partial_paths.size()) + " segments, expected " + std::to_string(expected);
    return v;
  }
  if (result.path.pairs_terminal_velocity_and_accel.size() != expected) {
    v.why = "pairs do not match the segments";
    return v;
  }
  const Pose2& first = result.path.partial_paths[0].points[0].pose;
  if (std::hypot(first.x - r.ego_pose.x, first.y - r.ego_pose.y) > 1e-4) {
    v.why = "the path does not start at the vehicle";
    return v;
  }
  v.why = oracle_problem(result.path, lanes, config.vehicle, params);
  v.passed = v.why.empty();
  (void)map;
  return v;
}

TEST(AutowareShoulderMap, EveryShoulderPullsOutWithEachPlanner) {
  if (!std::filesystem::exists(kMap)) {
    GTEST_SKIP() << "skipped: " << kMap << " is absent (the shared Autoware maps beside the checkout)";
  }
  const auto map = load_lanelet_map(kMap);
  ASSERT_EQ(map->lanelets().size(), 371u);
  ASSERT_EQ(map->count(LaneletSubtype::kRoadShoulder), 95u);
  const Config config = load_config(std::string(PULLOUT_SOURCE_DIR) + "/config/pullout.yaml");
  std::vector<Polygon> lanes;
  for (const Lanelet& ll : map->lanelets()) {
    if (auto lane = to_lane(ll)) lanes.push_back(lane_polygon(*lane));
  }
  const double kTen = 10.0 * kPi / 180.0;
  std::map<PlannerType, std::size_t> passed;
  std::map<PlannerType, std::vector<std::string>> failures;
  std::size_t shoulders = 0;
  for (const Lanelet& shoulder : map->lanelets()) {
    if (shoulder.subtype != LaneletSubtype::kRoadShoulder) continue;
    ++shoulders;
    const auto c = shoulder_case(*map, shoulder);
    ASSERT_TRUE(c) << "shoulder " << shoulder.id << " has no road beside it";
    for (PlannerType type : {PlannerType::kShift, PlannerType::kGeometric}) {
      bool all = true;
      for (double yaw : {0.0, kTen, -kTen}) {
        const Verdict v = plan_one(*map, map, config, type, *c, yaw, lanes);
        if (!v.passed) {
          all = false;
          failures[type].push_back("shoulder " + std::to_string(shoulder.id) + " yaw " +
                                   std::to_string(static_cast<int>(std::lround(yaw * 180.0 / kPi))) + ": " + v.why);
        }
      }
      if (all) ++passed[type];
    }
  }
  EXPECT_EQ(shoulders, 95u);
  for (PlannerType type : {PlannerType::kShift, PlannerType::kGeometric}) {
    std::string text;
    for (const auto& f : failures[type]) text += "  " + f + "\n";
    std::cout << to_string(type) << ": " << passed[type] << " of " << shoulders << " shoulder lanelets pass\n" << text;
  }
}

// ---- a start on a road lane (Autoware pulls out from a lane's centerline too) ----

struct SharedMapFile {
  const char* folder;
};
const SharedMapFile kSharedMaps[] = {{"autoware_test_map"}, {"autoware_intersection"}, {"autoware_road_shoulder"}};

class RoadLaneStart : public ::testing::TestWithParam<SharedMapFile> {};

// From the middle of every road lanelet at least 20 m long, on its centerline and along it, with
// the route ahead: the default search finds a forward path of one segment along the lane, inside
// the lanes by the oracle.
TEST_P(RoadLaneStart, FromTheCenterlineOfEveryRoadLanelet) {
  const std::string path = std::string(PULLOUT_SOURCE_DIR) + "/../shared/maps/" + GetParam().folder + "/lanelet2_map.osm";
  if (!std::filesystem::exists(path)) {
    GTEST_SKIP() << "skipped: " << path << " is absent (the shared Autoware maps beside the checkout)";
  }
  const auto map = load_lanelet_map(path);
  const Config config = load_config(std::string(PULLOUT_SOURCE_DIR) + "/config/pullout.yaml");
  std::vector<Polygon> lanes;
  for (const Lanelet& ll : map->lanelets()) {
    if (auto lane = to_lane(ll)) lanes.push_back(lane_polygon(*lane));
  }
  StartPlannerParameters params = config.start_planner;
  params.freespace_planner.enable_freespace_planner = false;
  const StartPlanner planner(config.vehicle, params, config.service.limits, map);
  std::size_t tried = 0;
  std::size_t passed = 0;
  std::map<PlannerType, std::size_t> by_planner;
  std::string failures;
  for (const Lanelet& road : map->lanelets()) {
    if (road.subtype != LaneletSubtype::kRoad || road.length_m < 20.0) continue;
    ++tried;
    const std::vector<std::int64_t> route = route_ahead(*map, *map->find(road.id));
    PullOutRequest r;
    r.vehicle_id = "road-start";
    r.request_id = 1;
    r.route_lanelet_ids = route;
    r.ego_pose = centerline_middle(road);
    r.goal_pose = route_end(*map, route);
    const PlanningResult result = planner.plan(r, StopCondition());
    std::string why;
    if (result.outcome != PlanningResult::Outcome::kFound) {
      why = result.outcome == PlanningResult::Outcome::kRejected ? format_issues(result.issues) : result.stop_reason;
    } else if (result.path.partial_paths.size() != 1 || direction_of(result.path.partial_paths[0]) <= 0.0) {
      why = std::to_string(result.path.partial_paths.size()) + " segments, expected 1 forward";
    } else {
      why = oracle_problem(result.path, lanes, config.vehicle, params);
    }
    if (why.empty()) {
      ++passed;
      ++by_planner[result.path.planner_type];
    } else {
      failures += "  road " + std::to_string(road.id) + ": " + why + "\n";
    }
  }
  std::cout << GetParam().folder << ": " << passed << " of " << tried << " road lanelets (shift "
            << by_planner[PlannerType::kShift] << ", geometric " << by_planner[PlannerType::kGeometric] << ")\n";
  EXPECT_GT(tried, 10u);
  EXPECT_EQ(passed, tried) << failures;
}

INSTANTIATE_TEST_SUITE_P(AutowareMaps, RoadLaneStart, ::testing::ValuesIn(kSharedMaps),
                         [](const ::testing::TestParamInfo<SharedMapFile>& info) {
                           return std::string(info.param.folder);
                         });

}  // namespace
}  // namespace pullout
