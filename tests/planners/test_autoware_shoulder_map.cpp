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

#include "../sampling.hpp"
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

// Shoulders passing at every possible start yaw, as measured when this test was written
// (geometric 37; 40 on main on 2026-12-03; 42 since the S may turn towards the road first where
// the end lies on the kerb side of the start's heading: 10988 and 10992, see solve_arc_pair; 45
// since the widened first arc keeps 1 cm inside the kerb-side room: 1954, 10993, 13518 at +10).
// Shift 40 on main on 2026-12-03; 43 since the shifted section is offset from the centerline
// averaged over +-2.5 m instead of point by point (678, 10988, 10997: the offset cusped inside the
// corners of the coarse centerline, curvature up to 0.71 1/m; see shift_pull_out.cpp).
constexpr std::size_t kShiftShoulderFloor = 43;
constexpr std::size_t kGeometricShoulderFloor = 45;

// [m] Neighbouring lanelets of these maps are sometimes a few centimetres apart instead of
// sharing a bound (675 and 676 on the road_shoulder map: 4.8 cm); the lane world joins lanes whose
// edges are within 5 cm (its shared-edge probe), and so does the oracle: a point in a gap between
// two lanelets at most this wide counts as inside.
constexpr double kClosedGap = 0.05;

const std::string kMap = std::string(PULLOUT_SOURCE_DIR) + "/../shared/maps/autoware_road_shoulder/lanelet2_map.osm";

struct Verdict {
  bool passed{false};
  std::string why;  // when not passed
};

// The path is inside the map's road and shoulder lanelets (expanded footprint as the planner's
// own lane check; for geometric, the oracle's geometric_lane_footprint from the first forward
// segment's start) and turns no tighter than the vehicle can, up to the end pose.
std::string oracle_problem(const PullOutPath& path, const std::vector<Polygon>& lanes, const VehicleInfo& vehicle,
                           const StartPlannerParameters& params) {
  Footprint fp = vehicle_footprint(vehicle, params.lane_departure_check_expansion_margin);
  if (path.planner_type == PlannerType::kGeometric) {
    for (const auto& seg : path.partial_paths) {
      if (direction_of(seg) > 0.0 && !seg.points.empty()) {
        fp = geometric_lane_footprint(vehicle, params, seg.points.front().pose, path.end_pose, lanes);
        break;
      }
    }
  }
  const double k_max = 1.0 / vehicle.min_turning_radius_m();
  for (std::size_t k = 0; k < path.partial_paths.size(); ++k) {
    const auto& points = path.partial_paths[k].points;
    if (points.size() < 2) return "segment " + std::to_string(k) + " has fewer than 2 points";
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Pose2& pose = points[i].pose;
      if (!footprint_in_lanes(fp, pose, lanes, kClosedGap)) {
        return "oracle: lane departure at segment " + std::to_string(k) + " point " + std::to_string(i);
      }
      if (i > 0 && i + 1 < points.size()) {
        const double kappa = menger_curvature(to_vec(points[i - 1].pose), to_vec(pose), to_vec(points[i + 1].pose));
        if (std::abs(kappa) > k_max * 1.02) {
          const Pose2& prev = points[i - 1].pose;
          const Pose2& next = points[i + 1].pose;
          return "oracle: curvature at segment " + std::to_string(k) + " point " + std::to_string(i) + ": " +
                 std::to_string(kappa) + " 1/m (limit " + std::to_string(k_max) + "), its neighbours " +
                 std::to_string(std::hypot(pose.x - prev.x, pose.y - prev.y)) + " / " +
                 std::to_string(std::hypot(next.x - pose.x, next.y - pose.y)) + " m away, " +
                 std::to_string(std::hypot(pose.x - path.end_pose.x, pose.y - path.end_pose.y)) +
                 " m from the end pose";
        }
      }
      if (k + 1 == path.partial_paths.size() && std::hypot(pose.x - path.end_pose.x, pose.y - path.end_pose.y) < 1e-6) {
        return "";  // beyond the end pose the path runs on along the road's centerline
      }
    }
  }
  return "";
}

Verdict plan_one(const std::shared_ptr<const LaneletMap>& map, const Config& config, PlannerType planner_type,
                 const ShoulderCase& c, double yaw_offset, const std::vector<Polygon>& lanes) {
  StartPlannerParameters params = config.start_planner;
  params.search_priority = {planner_type};
  params.enable_back = false;  // from the current pose, as Autoware's planner tests
  params.freespace_planner.enable_freespace_planner = false;
  params.divide_pull_out_path = true;
  const StartPlanner planner(config.vehicle, params, config.service.limits, map);
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
    std::vector<std::string> reasons;  // each distinct attempt outcome once
    for (const auto& a : result.evaluation_table) {
      const std::string d = describe(a);
      if (std::find(reasons.begin(), reasons.end(), d) == reasons.end()) reasons.push_back(d);
    }
    for (const auto& d : reasons) v.why += " [" + d + "]";
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
  return v;
}

// The map, the shipped configuration and the map's lane polygons, for each test of the map.
class AutowareShoulderMap : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!std::filesystem::exists(kMap)) {
      GTEST_SKIP() << "skipped: " << kMap << " is absent (the shared Autoware maps beside the checkout)";
    }
    map = load_lanelet_map(kMap);
    ASSERT_EQ(map->lanelets().size(), 371u);
    ASSERT_EQ(map->count(LaneletSubtype::kRoadShoulder), 95u);
    config = load_config(std::string(PULLOUT_SOURCE_DIR) + "/config/pullout.yaml");
    lanes = drivable_polygons(*map);
  }

  std::shared_ptr<const LaneletMap> map;
  Config config;
  std::vector<Polygon> lanes;
};

TEST_F(AutowareShoulderMap, EveryShoulderPullsOutWithEachPlanner) {
  const double kTen = 10.0 * kPi / 180.0;
  std::map<PlannerType, std::size_t> passed;
  std::map<PlannerType, std::vector<std::string>> failures;
  std::size_t shoulders = 0;
  std::size_t cases = 0;
  std::size_t possible_shoulders = 0;  // yaw 0 possible
  std::map<PlannerType, std::size_t> cases_passed;
  std::vector<std::string> outside;  // cases where the vehicle already stands outside the lanelets
  const Footprint body = vehicle_footprint(config.vehicle);
  for (const Lanelet& shoulder : map->lanelets()) {
    if (shoulder.subtype != LaneletSubtype::kRoadShoulder) continue;
    if (!test::sampled(shoulders++)) continue;
    // SONLY=<lanelet id> plans that shoulder alone (when looking into one; the floors then fail).
    if (std::getenv("SONLY") && std::to_string(shoulder.id) != std::getenv("SONLY")) continue;
    const auto c = shoulder_case(*map, shoulder);
    ASSERT_TRUE(c) << "shoulder " << shoulder.id << " has no road beside it";
    const LaneWorld own({*to_lane(shoulder)});
    const double width =
        own.lanes()[0].left.project(to_vec(c->ego)).distance + own.lanes()[0].right.project(to_vec(c->ego)).distance;
    std::map<PlannerType, bool> all{{PlannerType::kShift, true}, {PlannerType::kGeometric, true}};
    bool any = false;
    for (double yaw : {0.0, kTen, -kTen}) {
      const std::string name = "shoulder " + std::to_string(shoulder.id) + " yaw " +
                               std::to_string(static_cast<int>(std::lround(yaw * kRadToDeg)));
      // Standing there, the body already crosses the map's lanelets (a shoulder narrower than the
      // vehicle, or 3 m wide with the vehicle turned 10 degrees): no path can keep inside them, and
      // the lane departure check stays.
      Pose2 at = c->ego;
      at.yaw = normalize_angle(at.yaw + yaw);
      if (!footprint_in_lanes(body, at, lanes)) {
        outside.push_back(name + " (" + std::to_string(width).substr(0, 4) + " m wide)");
        if (yaw == 0.0) break;  // the turned starts are outside too, or meaningless
        continue;
      }
      if (yaw == 0.0) ++possible_shoulders;
      any = true;
      ++cases;
      for (PlannerType type : {PlannerType::kShift, PlannerType::kGeometric}) {
        const Verdict v = plan_one(map, config, type, *c, yaw, lanes);
        if (v.passed) {
          ++cases_passed[type];
        } else {
          all[type] = false;
          failures[type].push_back(name + " (" + std::to_string(width).substr(0, 4) + " m wide): " + v.why);
        }
      }
    }
    for (PlannerType type : {PlannerType::kShift, PlannerType::kGeometric}) {
      if (any && all[type]) ++passed[type];
    }
  }
  EXPECT_EQ(shoulders, 95u);
  std::cout << outside.size() << " of " << shoulders * 3
            << " starts stand outside the lanelets already (the shoulder is narrower than the vehicle there):\n";
  for (const auto& o : outside) std::cout << "  " << o << "\n";
  for (PlannerType type : {PlannerType::kShift, PlannerType::kGeometric}) {
    std::string text;
    for (const auto& f : failures[type]) text += "  " + f + "\n";
    std::cout << to_string(type) << ": " << passed[type] << " of " << possible_shoulders
              << " shoulder lanelets pass at every possible start yaw; " << cases_passed[type] << " of " << cases
              << " starts\n"
              << text;
  }
  // Floors measured on 2026-12-02 (bench/RESULTS.md): a change that loses a shoulder fails here
  // (in scripts/test, which plans every shoulder; the sanitizer build plans a sample).
  if (!test::kUnderSanitizer) {
    EXPECT_GE(passed[PlannerType::kShift], kShiftShoulderFloor);
    EXPECT_GE(passed[PlannerType::kGeometric], kGeometricShoulderFloor);
  }
  // A found path starts at the vehicle (the shift path started up to 0.6 m away where the
  // vehicle stood beside a corner of the road's centerline polyline).
  for (PlannerType type : {PlannerType::kShift, PlannerType::kGeometric}) {
    for (const auto& f : failures[type]) EXPECT_EQ(f.find("does not start at the vehicle"), std::string::npos) << f;
    // Every path the planner's own lane check accepts is inside the lanelets by the oracle too
    // (4 shift paths on shoulders 534 and 678 crossed a 4.8 cm gap between lanelets 675 and 676
    // that the lane world joins; the oracle now closes such gaps too, kClosedGap). The oracle's
    // curvature findings (shoulders 534, 678, 10988-10997) are reported, not asserted.
    for (const auto& f : failures[type]) EXPECT_EQ(f.find("oracle: lane departure"), std::string::npos) << f;
  }
}

// Shoulder 520 lies on the outside of a bend of about 60 degrees over 8 m of its road. With the
// vehicle turned 10 degrees towards the road, the end pose dx = 2 sqrt(R^2 - (R - d/2)^2) along
// the centerline lay 59 degrees round the bend, where no S of R_min reaches; the point dx ahead of
// and d beside the start in its own frame (Autoware's) lies 35 degrees round, where Autoware's S
// passes both its checks and stays in the shoulder and the road (bench/tools/
// autoware_geometric_oracle.py 520 --yaw -10). Before, all 10 candidates found no S and the
// shunting gave 12 segments.
TEST_F(AutowareShoulderMap, OnABendAwayFromTheShoulderTheTwoArcsEndWhereAutowaresDo) {
  const Lanelet* shoulder = nullptr;
  for (const Lanelet& ll : map->lanelets()) {
    if (ll.id == 520) shoulder = &ll;
  }
  ASSERT_NE(shoulder, nullptr);
  const auto c = shoulder_case(*map, *shoulder);
  ASSERT_TRUE(c);
  const Verdict v = plan_one(map, config, PlannerType::kGeometric, *c, -10.0 * kPi / 180.0, lanes);
  EXPECT_TRUE(v.passed) << v.why;
}

// ---- a start on a road lane (Autoware pulls out from a lane's centerline too) ----

struct SharedMapFile {
  const char* folder;
  std::size_t floor;  // road lanelets passing when this test was written (bench/RESULTS.md)
};
// autoware_intersection: 123 of 125; road 3010507's start already crosses the lanelets (a lane
// narrower than the vehicle), road 3200's path is an open finding (the oracle sees a departure at
// its second point that the planner's check does not).
const SharedMapFile kSharedMaps[] = {
    {"autoware_test_map", 10}, {"autoware_intersection", 123}, {"autoware_road_shoulder", 164}};

class RoadLaneStart : public ::testing::TestWithParam<SharedMapFile> {};

// From the middle of every road lanelet at least 20 m long, on its centerline and along it, with
// the route ahead: the default search finds a path that ends driving forward, inside the lanes by
// the oracle (one forward segment, or a reverse first where the search backs up).
TEST_P(RoadLaneStart, FromTheCenterlineOfEveryRoadLanelet) {
  const std::string path =
      std::string(PULLOUT_SOURCE_DIR) + "/../shared/maps/" + GetParam().folder + "/lanelet2_map.osm";
  if (!std::filesystem::exists(path)) {
    GTEST_SKIP() << "skipped: " << path << " is absent (the shared Autoware maps beside the checkout)";
  }
  const auto map = load_lanelet_map(path);
  const Config config = load_config(std::string(PULLOUT_SOURCE_DIR) + "/config/pullout.yaml");
  const std::vector<Polygon> lanes = drivable_polygons(*map);
  StartPlannerParameters params = config.start_planner;
  params.freespace_planner.enable_freespace_planner = false;
  const StartPlanner planner(config.vehicle, params, config.service.limits, map);
  std::size_t tried = 0;
  std::size_t passed = 0;
  std::map<PlannerType, std::size_t> by_planner;
  std::size_t reversing = 0;  // backed up first (the search's backward candidates)
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
    } else if (direction_of(result.path.partial_paths.back()) <= 0.0) {
      why = "the last segment does not drive forward";
    } else {
      why = oracle_problem(result.path, lanes, config.vehicle, params);
    }
    if (why.empty()) {
      ++passed;
      ++by_planner[result.path.planner_type];
      if (result.path.partial_paths.size() > 1) ++reversing;
    } else {
      failures += "  road " + std::to_string(road.id) + ": " + why + "\n";
    }
  }
  std::cout << GetParam().folder << ": " << passed << " of " << tried << " road lanelets (shift "
            << by_planner[PlannerType::kShift] << ", geometric " << by_planner[PlannerType::kGeometric] << "; "
            << reversing << " back up first)\n";
  EXPECT_GE(tried, 10u);
  EXPECT_GE(passed, GetParam().floor) << failures;
}

INSTANTIATE_TEST_SUITE_P(AutowareMaps, RoadLaneStart, ::testing::ValuesIn(kSharedMaps),
                         [](const ::testing::TestParamInfo<SharedMapFile>& info) {
                           return std::string(info.param.folder);
                         });

}  // namespace
}  // namespace pullout
