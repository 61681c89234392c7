// Planning on Lanelet2 maps: lane selection for a route, rejections naming the field, and a
// pull-out from every road_shoulder lanelet of the real Autoware maps in ../shared/maps (skipped,
// saying so, when that folder is absent), checked with the independent oracles.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "map_cases.hpp"
#include "path_oracles.hpp"
#include "pullout/collision/footprint.hpp"
#include "pullout/config/config.hpp"
#include "pullout/lanes/lane_world.hpp"
#include "pullout/maps/lanelet_map.hpp"
#include "pullout/maps/map_lanes.hpp"
#include "pullout/maps/osm_loader.hpp"
#include "pullout/model/names.hpp"
#include "pullout/pipeline/start_planner.hpp"

namespace pullout {
namespace {

using namespace oracle;  // NOLINT: the test's own helpers

const std::string kOwnMap = std::string(PULLOUT_SOURCE_DIR) + "/tests/maps/straight_shoulder.osm";
const std::string kSharedMaps = std::string(PULLOUT_SOURCE_DIR) + "/../shared/maps";

Config default_config() { return load_config(std::string(PULLOUT_SOURCE_DIR) + "/config/pullout.yaml"); }

PullOutRequest route_request(std::vector<std::int64_t> route, Pose2 ego, Pose2 goal) {
  PullOutRequest r;
  r.vehicle_id = "map-test";
  r.request_id = 1;
  r.route_lanelet_ids = std::move(route);
  r.ego_pose = ego;
  r.goal_pose = goal;
  return r;
}

bool has_issue(const std::vector<RequestIssue>& issues, const std::string& field, const std::string& words) {
  for (const auto& i : issues) {
    if (i.field == field && i.problem.find(words) != std::string::npos) return true;
  }
  return false;
}

std::string dump(const std::vector<RequestIssue>& issues) { return format_issues(issues); }

std::string dump(const std::vector<PlannerAttempt>& table) {
  std::string out;
  for (const auto& a : table) {
    out += "  planner " + std::to_string(static_cast<int>(a.planner)) + " margin " + std::to_string(a.margin_m) +
           " back " + std::to_string(a.backward_distance_m) + ": " + describe(a) + "\n";
  }
  return out;
}

// A found path starts at the vehicle, keeps its footprint inside the map's lanes and clear of the
// objects, and turns no tighter than the vehicle can.
void expect_drivable(const PlanningResult& r, const PullOutRequest& request, const LaneletMap& map,
                     const VehicleInfo& vehicle, const StartPlannerParameters& params) {
  ASSERT_EQ(r.outcome, PlanningResult::Outcome::kFound) << r.stop_reason << "\n"
                                                        << dump(r.issues) << dump(r.evaluation_table);
  const PullOutPath& path = r.path;
  ASSERT_EQ(path.pairs_terminal_velocity_and_accel.size(), path.partial_paths.size());
  // 0.1 mm: map coordinates are tens of kilometres from the origin, where the planners' arc-length
  // round trips lose a few micrometres.
  EXPECT_NEAR(path.partial_paths[0].points[0].pose.x, request.ego_pose.x, 1e-4);
  EXPECT_NEAR(path.partial_paths[0].points[0].pose.y, request.ego_pose.y, 1e-4);
  const std::vector<Polygon> lanes = drivable_polygons(map);
  std::vector<Polygon> obstacles;
  for (const Object& o : request.objects) obstacles.push_back(object_polygon(o));
  const double expansion = path.planner_type == PlannerType::kGeometric ? params.lane_departure_margin
                                                                        : params.lane_departure_check_expansion_margin;
  const Footprint lane_footprint = vehicle_footprint(vehicle, expansion);
  const Footprint footprint = vehicle_footprint(vehicle);
  const double k_max = 1.0 / vehicle.min_turning_radius_m();
  bool passed_end = false;
  for (std::size_t k = 0; k < path.partial_paths.size() && !passed_end; ++k) {
    const auto& points = path.partial_paths[k].points;
    ASSERT_GE(points.size(), 2u);
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Pose2& pose = points[i].pose;
      EXPECT_TRUE(footprint_in_lanes(lane_footprint, pose, lanes))
          << "lane departure at segment " << k << " point " << i;
      for (const Polygon& o : obstacles) {
        EXPECT_GT(polygon_distance(footprint_polygon(footprint, pose), o), 0.0) << "contact at " << k << "/" << i;
      }
      for (std::int64_t id : points[i].lane_ids) EXPECT_TRUE(map.find(id)) << "lane id " << id << " is not on the map";
      if (i > 0 && i + 1 < points.size()) {
        const Vec2 a = to_vec(points[i - 1].pose);
        const Vec2 b = to_vec(pose);
        const Vec2 c = to_vec(points[i + 1].pose);
        const double cross = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
        const double denom = (b - a).norm() * (c - b).norm() * (c - a).norm();
        if (denom > 1e-12) EXPECT_LE(std::abs(2.0 * cross / denom), k_max * 1.02) << "curvature at " << k << "/" << i;
      }
      // Beyond the end pose the path runs on along the road centerline: checked up to there.
      if (direction_of(path.partial_paths[k]) > 0.0 &&
          std::hypot(pose.x - path.end_pose.x, pose.y - path.end_pose.y) < 1e-6) {
        passed_end = true;
        break;
      }
    }
  }
}

// ---- the project's own map ----

class OwnMap : public ::testing::Test {
 protected:
  void SetUp() override {
    map_ = load_lanelet_map(kOwnMap);
    config_ = default_config();
  }
  StartPlanner planner() const {
    return StartPlanner(config_.vehicle, config_.start_planner, config_.service.limits, map_);
  }
  MapLaneOptions options() const {
    MapLaneOptions o;
    o.start_tolerance_m = config_.vehicle.width_m() / 2.0;
    return o;
  }
  std::shared_ptr<const LaneletMap> map_;
  Config config_;
};

TEST_F(OwnMap, PullsOutFromTheShoulderOntoTheRoute) {
  PullOutRequest r = route_request({101, 102, 103}, {20.0, 3.25, 0.0}, {180.0, 0.0, 0.0});
  Object car;
  car.id = 5;
  car.object_class = ObjectClass::kCar;
  car.pose = {32.0, 3.25, 0.0};
  r.objects.push_back(car);
  const PlanningResult result = planner().plan(r, StopCondition());
  expect_drivable(result, r, *map_, config_.vehicle, config_.start_planner);
  EXPECT_EQ(result.path.planner_type, PlannerType::kShift);
  EXPECT_TRUE(planner().validate(r).empty());
}

TEST_F(OwnMap, SelectsTheShoulderSequenceAndTheRouteAroundTheVehicle) {
  const MapLanes lanes = select_map_lanes(*map_, route_request({101, 102, 103}, {20.0, 3.25, 0.0}, {}), options());
  ASSERT_TRUE(lanes.issues.empty()) << dump(lanes.issues);
  EXPECT_EQ(lanes.road_ids, (std::vector<std::int64_t>{101, 102, 103}));
  EXPECT_EQ(lanes.pull_out_ids, (std::vector<std::int64_t>{201, 202}));
  EXPECT_EQ(lanes.lanes.size(), 5u);
  // On the road itself: no shoulder lanes, the road is the pull-out lane.
  const MapLanes on_road = select_map_lanes(*map_, route_request({101, 102}, {20.0, 0.0, 0.0}, {}), options());
  ASSERT_TRUE(on_road.issues.empty()) << dump(on_road.issues);
  EXPECT_TRUE(on_road.pull_out_ids.empty());
}

TEST_F(OwnMap, ExtendsAShortRouteBackwardAndForward) {
  // Route of one lanelet, the vehicle beside its start: 25 m behind come from 101, 300 m ahead
  // from 103 (the map ends there).
  const MapLanes lanes = select_map_lanes(*map_, route_request({102}, {65.0, 3.25, 0.0}, {}), options());
  ASSERT_TRUE(lanes.issues.empty()) << dump(lanes.issues);
  EXPECT_EQ(lanes.road_ids, (std::vector<std::int64_t>{101, 102, 103}));
  // A long route is cut to the window around the vehicle.
  MapLaneOptions short_window = options();
  short_window.backward_length_m = 10.0;
  short_window.forward_length_m = 10.0;
  const MapLanes cut = select_map_lanes(*map_, route_request({101, 102, 103}, {65.0, 3.25, 0.0}, {}), short_window);
  EXPECT_EQ(cut.road_ids, (std::vector<std::int64_t>{101, 102, 103}));
  const MapLanes cut_front =
      select_map_lanes(*map_, route_request({101, 102, 103}, {150.0, 0.0, 0.0}, {}), short_window);
  EXPECT_EQ(cut_front.road_ids, (std::vector<std::int64_t>{102, 103}));
}

TEST_F(OwnMap, BadRoutesAreRejectedNamingTheField) {
  const Pose2 ego{20.0, 3.25, 0.0};
  const auto issues = [&](std::vector<std::int64_t> route, Pose2 at) {
    return planner().plan(route_request(std::move(route), at, {180.0, 0.0, 0.0}), StopCondition()).issues;
  };
  auto i = issues({101, 4242}, ego);
  EXPECT_TRUE(has_issue(i, "route_lanelet_ids[1]", "unknown lanelet id 4242")) << dump(i);
  i = issues({101, 103}, ego);
  EXPECT_TRUE(has_issue(i, "route_lanelet_ids[1]", "the route is not connected")) << dump(i);
  i = issues({201, 202}, ego);
  EXPECT_TRUE(has_issue(i, "route_lanelet_ids[0]", "road_shoulder lanelet, not a road")) << dump(i);
  i = issues({401}, ego);
  EXPECT_TRUE(has_issue(i, "route_lanelet_ids[0]", "crosswalk")) << dump(i);
  i = issues({101, 102, 101}, ego);
  EXPECT_TRUE(has_issue(i, "route_lanelet_ids[2]", "listed twice")) << dump(i);
  i = issues({101, 102}, {500.0, 500.0, 0.0});
  EXPECT_TRUE(has_issue(i, "ego_pose", "is on no road or road_shoulder lanelet")) << dump(i);
  i = issues({101}, {20.0, 9.0, 0.0});
  EXPECT_TRUE(has_issue(i, "ego_pose", "the nearest, lanelet 201, is 4.25 m away")) << dump(i);
  i = issues({103}, ego);
  EXPECT_TRUE(has_issue(i, "route_lanelet_ids", "does not pass by the vehicle")) << dump(i);
  // Lanes and a route at once.
  PullOutRequest both = route_request({101}, ego, {});
  both.lanes.push_back(to_lane(map_->lanelet(*map_->find(101))).value());
  EXPECT_TRUE(has_issue(planner().plan(both, StopCondition()).issues, "lanes", "not both"));
  // No map loaded: the request says so.
  const StartPlanner no_map(config_.vehicle, config_.start_planner);
  EXPECT_TRUE(has_issue(no_map.plan(route_request({101}, ego, {}), StopCondition()).issues, "route_lanelet_ids",
                        "no Lanelet2 map is loaded"));
}

// ---- routes with lane-change neighbours: the project's own two-lane map ----

const std::string kTwoLaneMap = std::string(PULLOUT_SOURCE_DIR) + "/tests/maps/two_lane_road.osm";

class TwoLaneMap : public OwnMap {
 protected:
  void SetUp() override {
    map_ = load_lanelet_map(kTwoLaneMap);
    config_ = default_config();
  }
};

PullOutRequest segment_request(std::vector<RouteSegment> segments, Pose2 ego, Pose2 goal) {
  PullOutRequest r = route_request({}, ego, goal);
  r.route_segments = std::move(segments);
  return r;
}

// The shoulder on the right of the right lane; the route's preferred lane changes to the left lane.
const Pose2 kOnTheShoulder{20.0, -3.25, 0.0};
const Pose2 kLeftLaneEnd{190.0, 3.5, 0.0};
const std::vector<RouteSegment> kLaneChangeRoute{{111, {111, 121}}, {122, {112, 122}}, {123, {113, 123}}};

TEST_F(TwoLaneMap, RouteSegmentsWithLaneChangeNeighboursPlan) {
  const PullOutRequest r = segment_request(kLaneChangeRoute, kOnTheShoulder, kLeftLaneEnd);
  const MapLanes lanes = select_map_lanes(*map_, r, options());
  ASSERT_TRUE(lanes.issues.empty()) << dump(lanes.issues);
  // The road lanes follow successors through the segments; the neighbours are lanes too.
  EXPECT_EQ(lanes.road_ids, (std::vector<std::int64_t>{111, 112, 113}));
  EXPECT_EQ(lanes.pull_out_ids, (std::vector<std::int64_t>{211, 212}));
  EXPECT_EQ(lanes.neighbour_ids, (std::vector<std::int64_t>{121, 122, 123}));
  EXPECT_EQ(lanes.lanes.size(), 8u);
  const PlanningResult result = planner().plan(r, StopCondition());
  expect_drivable(result, r, *map_, config_.vehicle, config_.start_planner);
  ASSERT_TRUE(result.world);
  const auto has_lane = [&](std::int64_t id) {
    return std::any_of(result.world->lanes.begin(), result.world->lanes.end(),
                       [id](const Lane& l) { return l.id == id; });
  };
  EXPECT_TRUE(has_lane(121)) << "the departure checks use the segments' neighbours";
  // The same route as ids: a lanelet after a lane change (122 follows 121, the neighbour of 111)
  // was rejected as "not connected"; it plans, the neighbour joining the lanes.
  const PullOutRequest by_ids = route_request({111, 122, 123}, kOnTheShoulder, kLeftLaneEnd);
  const MapLanes id_lanes = select_map_lanes(*map_, by_ids, options());
  ASSERT_TRUE(id_lanes.issues.empty()) << dump(id_lanes.issues);
  EXPECT_EQ(id_lanes.neighbour_ids, (std::vector<std::int64_t>{121}));
  expect_drivable(planner().plan(by_ids, StopCondition()), by_ids, *map_, config_.vehicle, config_.start_planner);
  // Plain ids along one lane take no neighbour.
  const MapLanes plain = select_map_lanes(*map_, route_request({111, 112, 113}, kOnTheShoulder, {}), options());
  EXPECT_TRUE(plain.neighbour_ids.empty());
}

TEST_F(TwoLaneMap, DisconnectedRoutesAreStillRejectedNamingTheField) {
  const auto issues_of = [&](const PullOutRequest& r) { return planner().plan(r, StopCondition()).issues; };
  // Ids: 123 follows neither 111 nor its neighbour 121.
  auto i = issues_of(route_request({111, 123}, kOnTheShoulder, kLeftLaneEnd));
  EXPECT_TRUE(has_issue(i, "route_lanelet_ids[1]", "the route is not connected")) << dump(i);
  // Segments: nothing of segment 1 follows segment 0.
  i = issues_of(segment_request({{111, {111, 121}}, {123, {113, 123}}}, kOnTheShoulder, kLeftLaneEnd));
  EXPECT_TRUE(has_issue(i, "route_segments[1]", "the route is not connected")) << dump(i);
  // A primitive that is not beside the preferred lanelet.
  i = issues_of(segment_request({{111, {111, 112}}}, kOnTheShoulder, kLeftLaneEnd));
  EXPECT_TRUE(has_issue(i, "route_segments[0].primitives[1]", "not a lane-change neighbour")) << dump(i);
  // The preferred lanelet missing from the primitives; unknown ids; shoulders.
  i = issues_of(segment_request({{111, {121}}}, kOnTheShoulder, kLeftLaneEnd));
  EXPECT_TRUE(has_issue(i, "route_segments[0].preferred_primitive", "not among the segment's primitives")) << dump(i);
  i = issues_of(segment_request({{111, {111, 4242}}}, kOnTheShoulder, kLeftLaneEnd));
  EXPECT_TRUE(has_issue(i, "route_segments[0].primitives[1]", "unknown lanelet id 4242")) << dump(i);
  i = issues_of(segment_request({{4242, {}}}, kOnTheShoulder, kLeftLaneEnd));
  EXPECT_TRUE(has_issue(i, "route_segments[0].preferred_primitive", "unknown lanelet id 4242")) << dump(i);
  i = issues_of(segment_request({{111, {111, 211}}}, kOnTheShoulder, kLeftLaneEnd));
  EXPECT_TRUE(has_issue(i, "route_segments[0].primitives[1]", "not a road")) << dump(i);
  i = issues_of(segment_request({{111, {111}}, {112, {112, 111}}}, kOnTheShoulder, kLeftLaneEnd));
  EXPECT_TRUE(has_issue(i, "route_segments[1].primitives[1]", "listed twice")) << dump(i);
  // Both forms at once.
  PullOutRequest both = segment_request(kLaneChangeRoute, kOnTheShoulder, kLeftLaneEnd);
  both.route_lanelet_ids = {111};
  i = issues_of(both);
  EXPECT_TRUE(has_issue(i, "route_segments", "not both")) << dump(i);
  // Far from the vehicle.
  i = issues_of(segment_request({{113, {113, 123}}}, kOnTheShoulder, kLeftLaneEnd));
  EXPECT_TRUE(has_issue(i, "route_segments", "does not pass by the vehicle")) << dump(i);
}

// ---- the real Autoware maps (../shared/maps) ----

struct SharedMap {
  const char* folder;
  std::size_t lanelets;
  std::size_t shoulders;
};
const SharedMap kSharedMapList[] = {{"autoware_test_map", 48, 4}, {"autoware_intersection", 161, 5}};

std::string shared_map_path(const SharedMap& m) { return kSharedMaps + "/" + m.folder + "/lanelet2_map.osm"; }

#define SKIP_WITHOUT(path)                                                                                \
  if (!std::filesystem::exists(path)) {                                                                   \
    GTEST_SKIP() << "skipped: " << (path) << " is absent (the shared Autoware maps beside the checkout)"; \
  }

class SharedMaps : public ::testing::TestWithParam<SharedMap> {};

TEST_P(SharedMaps, LoadWithTheirLaneletAndShoulderCounts) {
  const std::string path = shared_map_path(GetParam());
  SKIP_WITHOUT(path);
  const auto map = load_lanelet_map(path);
  EXPECT_EQ(map->lanelets().size(), GetParam().lanelets);
  EXPECT_EQ(map->count(LaneletSubtype::kRoadShoulder), GetParam().shoulders);
}

// From the middle of every road_shoulder lanelet, on its centerline, onto the road beside it.
TEST_P(SharedMaps, PullOutFromEveryShoulderLanelet) {
  const std::string path = shared_map_path(GetParam());
  SKIP_WITHOUT(path);
  const auto map = load_lanelet_map(path);
  const Config config = default_config();
  const StartPlanner planner(config.vehicle, config.start_planner, config.service.limits, map);
  std::size_t tried = 0;
  for (const Lanelet& shoulder : map->lanelets()) {
    if (shoulder.subtype != LaneletSubtype::kRoadShoulder) continue;
    SCOPED_TRACE("shoulder lanelet " + std::to_string(shoulder.id));
    // The adjacent road: the neighbour sharing the shoulder's bound.
    std::optional<std::size_t> road;
    for (const auto* side : {&shoulder.left_neighbours, &shoulder.right_neighbours}) {
      for (std::size_t n : *side) {
        if (map->lanelet(n).subtype == LaneletSubtype::kRoad) road = n;
      }
    }
    ASSERT_TRUE(road) << "no road beside the shoulder";
    // The route: that road and its successors (straight first) for about 100 m.
    std::vector<std::int64_t> route{map->lanelet(*road).id};
    double length = map->lanelet(*road).length_m;
    for (std::size_t cur = *road; length < 100.0;) {
      std::optional<std::size_t> next;
      for (std::size_t s : map->lanelet(cur).successors) {
        const Lanelet& ll = map->lanelet(s);
        if (ll.subtype != LaneletSubtype::kRoad) continue;
        if (!next || ll.turn_direction == TurnDirection::kStraight) next = s;
      }
      if (!next) break;
      route.push_back(map->lanelet(*next).id);
      length += map->lanelet(*next).length_m;
      cur = *next;
    }
    // The vehicle's pose: the middle of the shoulder's centerline (derived as the core does). Where
    // the shoulder is narrower than the vehicle (the intersection map's are 0.5 to 1.8 m wide) the
    // vehicle stands kerb-side instead, its outer side 5 cm inside the shoulder's outer bound: on
    // the centerline it would already stand outside every lanelet, and no path can then stay inside.
    const LaneWorld shoulder_world({*to_lane(shoulder)});
    const LaneGeometry& geometry = shoulder_world.lanes()[0];
    const Polyline& center = geometry.centerline;
    Pose2 ego = center.pose_at(center.length() / 2.0);
    const bool road_on_right = map->lanelet(*road).id != shoulder.id &&
                               std::find(shoulder.right_neighbours.begin(), shoulder.right_neighbours.end(), *road) !=
                                   shoulder.right_neighbours.end();
    const Polyline& outer = road_on_right ? geometry.left : geometry.right;
    const double half_width = outer.project(to_vec(ego)).distance;
    const double needed = config.vehicle.width_m() / 2.0 + 0.05;
    if (half_width < needed) {
      const double shift = (needed - half_width) * (road_on_right ? -1.0 : 1.0);  // towards the road
      ego.x -= std::sin(ego.yaw) * shift;
      ego.y += std::cos(ego.yaw) * shift;
    }
    PullOutRequest r = route_request(route, ego, {});
    const LaneWorld last({*to_lane(map->lanelet(*map->find(route.back())))});
    r.goal_pose = last.lanes()[0].centerline.pose_at(last.lanes()[0].centerline.length());
    const PlanningResult result = planner.plan(r, StopCondition());
    expect_drivable(result, r, *map, config.vehicle, config.start_planner);
    ++tried;
  }
  EXPECT_EQ(tried, GetParam().shoulders);
}

TEST(SharedMapTopology, SpotChecks) {
  const std::string test_map = shared_map_path(kSharedMapList[0]);
  const std::string intersection = shared_map_path(kSharedMapList[1]);
  SKIP_WITHOUT(test_map);
  SKIP_WITHOUT(intersection);
  const auto a = load_lanelet_map(test_map);
  const auto id = [](const LaneletMap& m, std::int64_t id) -> const Lanelet& { return m.lanelet(*m.find(id)); };
  const auto ids = [](const LaneletMap& m, const std::vector<std::size_t>& idx) {
    std::vector<std::int64_t> out;
    for (std::size_t i : idx) out.push_back(m.lanelet(i).id);
    std::sort(out.begin(), out.end());
    return out;
  };
  // The shoulder chain along the test map's straight road, each beside its road lanelet.
  EXPECT_EQ(ids(*a, id(*a, 10287).successors), std::vector<std::int64_t>{10291});
  EXPECT_EQ(ids(*a, id(*a, 10291).successors), std::vector<std::int64_t>{10303});
  EXPECT_EQ(ids(*a, id(*a, 10287).right_neighbours), std::vector<std::int64_t>{9297});
  EXPECT_EQ(ids(*a, id(*a, 9297).left_neighbours), std::vector<std::int64_t>{10287});
  EXPECT_EQ(ids(*a, id(*a, 9297).successors), std::vector<std::int64_t>{9102});
  EXPECT_EQ(ids(*a, id(*a, 9297).predecessors), (std::vector<std::int64_t>{15, 17}));
  EXPECT_EQ(id(*a, 15).turn_direction, TurnDirection::kLeft);
  EXPECT_NEAR(id(*a, 9297).speed_limit_mps, 30.0 / 3.6, 1e-9);
  const auto b = load_lanelet_map(intersection);
  // Into the intersection: left turn 1200 and straight 1100 follow 1010.
  EXPECT_EQ(ids(*b, id(*b, 1010).successors), (std::vector<std::int64_t>{1100, 1200}));
  EXPECT_EQ(id(*b, 1100).turn_direction, TurnDirection::kStraight);
  EXPECT_EQ(ids(*b, id(*b, 3010879).successors), std::vector<std::int64_t>{3010907});
  // The shoulder on the right of road 3014.
  EXPECT_EQ(ids(*b, id(*b, 3008188).left_neighbours), std::vector<std::int64_t>{3014});
  EXPECT_EQ(ids(*b, id(*b, 3014).right_neighbours), std::vector<std::int64_t>{3008188});
}

INSTANTIATE_TEST_SUITE_P(AutowareMaps, SharedMaps, ::testing::ValuesIn(kSharedMapList),
                         [](const ::testing::TestParamInfo<SharedMap>& info) {
                           return std::string(info.param.folder);
                         });

}  // namespace
}  // namespace pullout
