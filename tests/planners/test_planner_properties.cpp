// Properties of every planner on the scenario files: each case states whether its planner finds
// a path there, and what it returns as found must be a path a vehicle can drive. The oracles
// (path_oracles.hpp) are independent of the planners' own checks: a separating-axis overlap test
// and a vertex-to-edge distance instead of FCL or the freespace grid checker, boundary sampling
// against the raw lane polygons instead of the lane world's outline, Menger curvature of three
// consecutive points.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "path_oracles.hpp"
#include "pullout/collision/footprint.hpp"
#include "pullout/config/scenario.hpp"
#include "pullout/model/names.hpp"
#include "pullout/pipeline/start_planner.hpp"

namespace pullout {
namespace {

using namespace oracle;  // NOLINT: the test's own helpers

Scenario load(const std::string& name) {
  return load_scenario(std::string(PULLOUT_SOURCE_DIR) + "/tests/scenarios/" + name + ".yaml");
}

// One planner on one scenario. A lane planner (shift, geometric, clothoid) runs alone: it is the
// only entry of search_priority and the freespace fallback is off, so a found path is its own.
// kFreespace runs the scenario's own planner list, in which the lane planners fail and the
// freespace fallback must win.
struct PropertyCase {
  const char* scenario;
  PlannerType planner;
  bool found;  // whether this planner finds a path here (consistent with the file's `expect:`)
};

std::ostream& operator<<(std::ostream& os, const PropertyCase& c) {
  return os << c.scenario << "/" << to_string(c.planner) << (c.found ? " finds" : " finds nothing");
}

const PropertyCase kCases[] = {
    {"straight_shoulder", PlannerType::kShift, true},
    {"straight_shoulder", PlannerType::kGeometric, true},
    {"straight_shoulder", PlannerType::kClothoid, true},
    {"curved_road", PlannerType::kShift, true},
    {"curved_road", PlannerType::kGeometric, true},
    {"curved_road", PlannerType::kClothoid, true},
    {"parked_car_ahead", PlannerType::kShift, true},
    {"parked_car_ahead", PlannerType::kGeometric, true},
    {"parked_car_ahead", PlannerType::kClothoid, true},
    {"boxed_in", PlannerType::kShift, false},
    {"boxed_in", PlannerType::kGeometric, false},
    {"boxed_in", PlannerType::kClothoid, false},
    {"parallel_spot", PlannerType::kShift, false},
    {"parallel_spot", PlannerType::kGeometric, true},
    {"parallel_spot", PlannerType::kClothoid, true},
    {"perpendicular_bay", PlannerType::kShift, false},
    {"perpendicular_bay", PlannerType::kGeometric, true},
    {"perpendicular_bay", PlannerType::kClothoid, true},
    {"parallel_spot_reverse", PlannerType::kShift, true},
    {"parallel_spot_reverse", PlannerType::kGeometric, true},
    {"parallel_spot_reverse", PlannerType::kClothoid, true},
    {"car_close_ahead", PlannerType::kShift, true},
    {"car_close_ahead", PlannerType::kGeometric, true},
    {"car_close_ahead", PlannerType::kClothoid, true},
    {"full_search", PlannerType::kShift, false},
    {"full_search", PlannerType::kGeometric, false},
    {"full_search", PlannerType::kClothoid, false},
    {"clothoid_only", PlannerType::kClothoid, true},
    {"single_lane_street", PlannerType::kShift, false},
    {"single_lane_street", PlannerType::kGeometric, true},
    {"single_lane_street_left_hand", PlannerType::kShift, false},
    {"single_lane_street_left_hand", PlannerType::kGeometric, true},
    {"freespace_boxed_in", PlannerType::kFreespace, true},
    {"freespace_perpendicular_bay", PlannerType::kFreespace, true},
    {"freespace_parking_lot", PlannerType::kFreespace, true},
};

// The scenario's parameters and request for the case. A scenario's `planner: search_priority`
// is also a request override (so that a scenario sent to the service plans the same), which would
// win over the parameters: the request's override names the case's planner too.
StartPlannerParameters case_parameters(const Scenario& sc, PlannerType planner) {
  StartPlannerParameters params = sc.parameters;
  if (planner != PlannerType::kFreespace) {
    params.search_priority = {planner};
    params.freespace_planner.enable_freespace_planner = false;
  }
  return params;
}
PullOutRequest case_request(const Scenario& sc, PlannerType planner) {
  PullOutRequest request = sc.request;
  if (planner != PlannerType::kFreespace) request.overrides.search_priority = {planner};
  return request;
}

// ---- the property test ----

class PlannerProperties : public ::testing::TestWithParam<PropertyCase> {};

TEST_P(PlannerProperties, FoundPathsAreDrivable) {
  const PropertyCase& c = GetParam();
  const Scenario sc = load(c.scenario);
  const StartPlannerParameters params = case_parameters(sc, c.planner);
  const StartPlanner planner(sc.vehicle, params);
  const PlanningResult r = planner.plan(case_request(sc, c.planner), StopCondition());
  if (!c.found) {
    // Nothing to find: it must come as a stop path with reasons.
    ASSERT_NE(r.outcome, PlanningResult::Outcome::kFound) << to_string(r.path.planner_type) << " found a path";
    EXPECT_FALSE(r.path.found);
    EXPECT_EQ(r.path.planner_type, PlannerType::kStop);
    EXPECT_FALSE(r.path.reasons.empty());
    ASSERT_FALSE(r.path.partial_paths.empty());
    for (const auto& p : r.path.partial_paths.at(0).points) EXPECT_DOUBLE_EQ(p.longitudinal_velocity_mps, 0.0);
    return;
  }
  ASSERT_EQ(r.outcome, PlanningResult::Outcome::kFound) << "expected a path: " << r.stop_reason;
  const PullOutPath& path = r.path;
  ASSERT_TRUE(path.found);
  ASSERT_EQ(path.planner_type, c.planner) << "the path comes from another planner";
  ASSERT_GE(path.partial_paths.size(), 1u);
  ASSERT_EQ(path.pairs_terminal_velocity_and_accel.size(), path.partial_paths.size()) << "one pair per segment";
  ASSERT_EQ(r.evaluation_table.back().outcome, AttemptOutcome::kSuccess);
  const bool freespace = c.planner == PlannerType::kFreespace;
  const FreespaceParameters& fp = params.freespace_planner;

  // Starts at the vehicle.
  EXPECT_NEAR(path.partial_paths[0].points[0].pose.x, sc.request.ego_pose.x, 1e-9);
  EXPECT_NEAR(path.partial_paths[0].points[0].pose.y, sc.request.ego_pose.y, 1e-9);

  std::vector<Polygon> obstacles;
  for (const Object& o : sc.request.objects) obstacles.push_back(object_polygon(o));
  const OccupancyGrid* grid = sc.request.occupancy_grid ? &*sc.request.occupancy_grid : nullptr;
  const int threshold = fp.costmap_configs.obstacle_threshold;
  std::vector<Polygon> lanes;
  for (const Lane& l : sc.request.lanes) lanes.push_back(lane_polygon(l));
  const Footprint body = vehicle_footprint(sc.vehicle);
  // The clearance each planner promises up to the end pose: the winning margin of a lane planner;
  // for freespace, the footprint grown by half of vehicle_shape_margin is clear of every occupied
  // cell, and the costmap marks every cell an object touches, so the body keeps that distance.
  const double margin = freespace ? 0.5 * fp.vehicle_shape_margin : r.evaluation_table.back().margin_m;
  // The footprint that must stay inside the lanes: the lane planners' departure expansion (for
  // geometric, see geometric_lane_footprint); the freespace costmap frees only cells entirely
  // inside the lanes.
  const double expansion = freespace                              ? 0.5 * fp.vehicle_shape_margin
                           : c.planner == PlannerType::kGeometric ? params.lane_departure_margin
                                                                  : params.lane_departure_check_expansion_margin;
  Footprint lane_footprint = vehicle_footprint(sc.vehicle, expansion);
  if (c.planner == PlannerType::kGeometric) {
    // The geometric part starts at the first forward segment (after a reverse leg, if any).
    for (const auto& seg : path.partial_paths) {
      if (direction_of(seg) > 0.0) {
        lane_footprint = geometric_lane_footprint(sc.vehicle, params, seg.points.front().pose, path.end_pose, lanes);
        break;
      }
    }
  }
  // Where the margin applies: up to the end pose, plus 10 m for shift
  // (shift_collision_check_distance_from_end); beyond that only contact is excluded.
  const double margin_until_end =
      c.planner == PlannerType::kShift ? params.shift_collision_check_distance_from_end : 0.0;
  // Distance from the forward start to the end pose, to know where the margin section ends.
  double end_distance = -1.0;
  {
    double d = 0.0;
    for (const auto& seg : path.partial_paths) {
      if (direction_of(seg) < 0.0) continue;
      for (std::size_t i = 0; i < seg.points.size(); ++i) {
        if (i > 0)
          d += std::hypot(seg.points[i].pose.x - seg.points[i - 1].pose.x,
                          seg.points[i].pose.y - seg.points[i - 1].pose.y);
        if (end_distance < 0 &&
            std::hypot(seg.points[i].pose.x - path.end_pose.x, seg.points[i].pose.y - path.end_pose.y) < 1e-6)
          end_distance = d;
      }
    }
    ASSERT_GE(end_distance, 0.0) << "end_pose is a point of the path";
  }

  const auto clearance_at = [&](const Pose2& pose) {
    double clearance = std::numeric_limits<double>::infinity();
    const Polygon rect = rectangle_at(body, pose);
    for (const Polygon& o : obstacles) clearance = std::min(clearance, polygon_distance(rect, o));
    return clearance;
  };

  bool passed_end = false;
  double forward_distance = 0.0;
  for (std::size_t k = 0; k < path.partial_paths.size() && !passed_end; ++k) {
    const PathWithLaneId& seg = path.partial_paths[k];
    ASSERT_GE(seg.points.size(), 2u) << "segment " << k;
    const double dir = direction_of(seg);
    ASSERT_NE(dir, 0.0) << "segment " << k << " has no motion";
    EXPECT_EQ(path.pairs_terminal_velocity_and_accel[k].velocity_mps > 0.0, dir > 0.0) << "pair sign, segment " << k;
    for (const auto& p : seg.points) {
      EXPECT_GE(p.longitudinal_velocity_mps * dir, 0.0) << "direction changes inside segment " << k;
    }
    if (k + 1 < path.partial_paths.size()) {
      const auto& a = seg.points.back();
      const auto& b = path.partial_paths[k + 1].points.front();
      EXPECT_LT(std::hypot(a.pose.x - b.pose.x, a.pose.y - b.pose.y), 1e-6) << "join " << k;
      EXPECT_LT(std::abs(normalize_angle(a.pose.yaw - b.pose.yaw)), 0.05) << "join heading " << k;
      if (direction_of(path.partial_paths[k + 1]) != dir) {
        EXPECT_DOUBLE_EQ(a.longitudinal_velocity_mps, 0.0) << "velocity 0 at the direction change after " << k;
      }
    }
    for (std::size_t i = 0; i < seg.points.size(); ++i) {
      const Pose2& pose = seg.points[i].pose;
      if (dir > 0.0 && i > 0) {
        forward_distance += std::hypot(pose.x - seg.points[i - 1].pose.x, pose.y - seg.points[i - 1].pose.y);
      }
      const double clearance = clearance_at(pose);
      EXPECT_GT(clearance, 0.0) << "contact at segment " << k << " point " << i;
      const bool margin_applies =
          freespace || (dir > 0.0 && forward_distance <= end_distance + margin_until_end + 1e-9);
      if (margin_applies) {
        // 1e-3: FCL's GJK and this oracle agree to well below a millimetre.
        EXPECT_GE(clearance, margin - 1e-3) << "margin at segment " << k << " point " << i;
      }
      if (grid != nullptr) {
        // The grid's occupied cells: the footprint grown by the margin touches none of them.
        const Footprint grown = vehicle_footprint(sc.vehicle, margin_applies ? margin - 1e-3 : 0.0);
        EXPECT_FALSE(overlaps_grid(*grid, threshold, rectangle_at(grown, pose)))
            << "occupied cell at segment " << k << " point " << i;
      }
      if (!lanes.empty()) {
        EXPECT_TRUE(footprint_in_lanes(lane_footprint, pose, lanes))
            << "lane departure at segment " << k << " point " << i;
      }
      if (dir > 0.0 && std::hypot(pose.x - path.end_pose.x, pose.y - path.end_pose.y) < 1e-6) {
        passed_end = true;
        break;
      }
    }
  }
  // Between the points too, every 5 cm: the body never touches an object (the whole path).
  for (std::size_t k = 0; k < path.partial_paths.size(); ++k) {
    for (const Pose2& pose : poses_along(path.partial_paths[k], 0.05)) {
      ASSERT_GT(clearance_at(pose), 0.0) << "contact between the points of segment " << k << " at (" << pose.x << ", "
                                         << pose.y << ")";
      if (grid != nullptr) {
        ASSERT_FALSE(overlaps_grid(*grid, threshold, rectangle_at(body, pose)))
            << "occupied cell between the points of segment " << k << " at (" << pose.x << ", " << pose.y << ")";
      }
    }
  }

  // Curvature within the vehicle's limit (freespace: its own max_turning_ratio of the steering),
  // from three consecutive points; 2 % covers the chords of the sampled arcs.
  const double k_max = freespace
                           ? std::tan(sc.vehicle.max_steer_angle_rad * fp.max_turning_ratio) / sc.vehicle.wheel_base_m
                           : 1.0 / sc.vehicle.min_turning_radius_m();
  for (std::size_t k = 0; k < path.partial_paths.size(); ++k) {
    const auto& pts = path.partial_paths[k].points;
    for (std::size_t i = 1; i + 1 < pts.size(); ++i) {
      const double kappa = menger_curvature(to_vec(pts[i - 1].pose), to_vec(pts[i].pose), to_vec(pts[i + 1].pose));
      EXPECT_LE(std::abs(kappa), k_max * 1.02) << "curvature at segment " << k << " point " << i;
    }
  }
}

std::string param_name(const ::testing::TestParamInfo<PropertyCase>& info) {
  return std::string(info.param.scenario) + "_" + to_string(info.param.planner);
}

INSTANTIATE_TEST_SUITE_P(Scenarios, PlannerProperties, ::testing::ValuesIn(kCases), param_name);

// The case table against the files: a scenario that expects no path has no case that finds one,
// and the planner a file expects to win finds a path alone.
TEST(PlannerPropertyCases, AgreeWithTheScenarioFiles) {
  bool clothoid_finds = false;
  bool freespace_finds = false;
  for (const PropertyCase& c : kCases) {
    const Scenario sc = load(c.scenario);
    ASSERT_TRUE(sc.expect.found.has_value()) << c.scenario << " states whether a path exists";
    if (!*sc.expect.found) {
      EXPECT_FALSE(c.found) << c;
    }
    if (sc.expect.planner == c.planner) {
      EXPECT_TRUE(c.found) << c;
    }
    clothoid_finds = clothoid_finds || (c.found && c.planner == PlannerType::kClothoid);
    freespace_finds = freespace_finds || (c.found && c.planner == PlannerType::kFreespace);
  }
  EXPECT_TRUE(clothoid_finds) << "some case checks a clothoid path";
  EXPECT_TRUE(freespace_finds) << "some case checks a freespace path";
}

// ---- the oracles themselves, on cases worked by hand ----

Polygon square(double x0, double y0, double side) {
  return {{x0, y0}, {x0 + side, y0}, {x0 + side, y0 + side}, {x0, y0 + side}};
}

TEST(PathOracles, SeparatingAxesAndDistanceOnWorkedCases) {
  const Polygon unit = square(0, 0, 1);
  // Side by side, 0.5 m apart: the x axis separates them by 0.5.
  EXPECT_NEAR(separating_gap(unit, square(1.5, 0, 1)), 0.5, 1e-12);
  EXPECT_NEAR(polygon_distance(unit, square(1.5, 0, 1)), 0.5, 1e-12);
  // Corner to corner: the best axis gap is 1, the distance sqrt(2).
  EXPECT_NEAR(separating_gap(unit, square(2, 2, 1)), 1.0, 1e-12);
  EXPECT_NEAR(polygon_distance(unit, square(2, 2, 1)), std::sqrt(2.0), 1e-12);
  // Overlapping and touching both count as contact.
  EXPECT_TRUE(polygons_overlap(unit, square(0.5, 0.5, 1)));
  EXPECT_TRUE(polygons_overlap(unit, square(1.0, 0.0, 1)));
  EXPECT_DOUBLE_EQ(polygon_distance(unit, square(1.0, 0.0, 1)), 0.0);
  // A diamond centred at (1.4, 1.4) with half diagonal 0.5: the bounding boxes overlap, only the
  // diagonal axis separates; its edge x + y = 2.3 lies 0.3 / sqrt(2) from the corner (1, 1).
  const Polygon diamond{{0.9, 1.4}, {1.4, 0.9}, {1.9, 1.4}, {1.4, 1.9}};
  EXPECT_FALSE(polygons_overlap(unit, diamond));
  EXPECT_NEAR(polygon_distance(unit, diamond), 0.3 / std::sqrt(2.0), 1e-12);
  EXPECT_TRUE(polygons_overlap(unit, Polygon{{0.7, 1.2}, {1.2, 0.7}, {1.7, 1.2}, {1.2, 1.7}}));
}

TEST(PathOracles, GridCellsCurvatureAndInterpolationOnWorkedCases) {
  OccupancyGrid g;
  g.resolution_m = 1.0;
  g.origin = {10.0, 20.0, 0.0};
  g.width = 10;
  g.height = 10;
  g.data.assign(100, 0);
  g.data[5 * 10 + 5] = 100;  // the cell [15, 16] x [25, 26]
  EXPECT_FALSE(overlaps_grid(g, 30, square(13.0, 25.0, 1.9)));
  EXPECT_TRUE(overlaps_grid(g, 30, square(13.0, 25.0, 2.0)));  // touches its side
  EXPECT_TRUE(overlaps_grid(g, 30, square(9.5, 22.0, 1.0)));   // leaves the grid
  g.data[5 * 10 + 5] = 29;                                     // below the threshold: free
  EXPECT_FALSE(overlaps_grid(g, 30, square(13.0, 25.0, 2.0)));
  // Three points of a circle of radius 5, turning left.
  const auto on_circle = [](double a) { return Vec2(5.0 * std::cos(a), 5.0 * std::sin(a)); };
  EXPECT_NEAR(menger_curvature(on_circle(0.0), on_circle(0.3), on_circle(0.7)), 0.2, 1e-12);
  EXPECT_NEAR(menger_curvature(on_circle(0.7), on_circle(0.3), on_circle(0.0)), -0.2, 1e-12);
  PathWithLaneId seg;
  seg.points = {{{0.0, 0.0, 0.0}, 1.0, {}}, {{1.0, 0.0, 0.1}, 1.0, {}}};
  const std::vector<Pose2> poses = poses_along(seg, 0.3);
  ASSERT_EQ(poses.size(), 5u);  // 4 steps of 0.25 m and the end
  EXPECT_NEAR(poses[1].x, 0.25, 1e-12);
  EXPECT_NEAR(poses[2].yaw, 0.05, 1e-12);
}

// ---- each scenario with its own planner list: what its `expect:` says ----

class ScenarioExpectations : public ::testing::TestWithParam<const char*> {};

TEST_P(ScenarioExpectations, MatchTheFile) {
  const Scenario sc = load(GetParam());
  const StartPlanner planner(sc.vehicle, sc.parameters, {}, sc.map);
  const PlanningResult r = planner.plan(sc.request, StopCondition());
  ASSERT_TRUE(sc.expect.found.has_value()) << "every bundled scenario states whether a path exists";
  EXPECT_EQ(r.path.found, *sc.expect.found) << r.stop_reason;
  if (sc.expect.planner) {
    EXPECT_EQ(to_string(r.path.planner_type), std::string(to_string(*sc.expect.planner)));
  }
  if (sc.expect.margin_m && r.path.found) {
    EXPECT_DOUBLE_EQ(r.evaluation_table.back().margin_m, *sc.expect.margin_m);
  }
  if (!r.path.found) {
    EXPECT_FALSE(r.path.reasons.empty());
    for (const auto& p : r.path.partial_paths[0].points) EXPECT_DOUBLE_EQ(p.longitudinal_velocity_mps, 0.0);
  }
}

// The map scenarios too (their path properties are checked in test_map_planning.cpp).
const char* const kExpectationScenarios[] = {"straight_shoulder",     "curved_road",
                                             "parked_car_ahead",      "boxed_in",
                                             "parallel_spot",         "perpendicular_bay",
                                             "parallel_spot_reverse", "car_close_ahead",
                                             "full_search",           "map_shoulder",
                                             "map_lane_change_route", "clothoid_only",
                                             "single_lane_street",    "single_lane_street_left_hand"};
INSTANTIATE_TEST_SUITE_P(Bundled, ScenarioExpectations, ::testing::ValuesIn(kExpectationScenarios));

TEST(ScenarioSpecifics, CarCloseAheadReversesFirst) {
  const Scenario sc = load("car_close_ahead");
  const PlanningResult r = StartPlanner(sc.vehicle, sc.parameters).plan(sc.request, StopCondition());
  ASSERT_TRUE(r.path.found);
  ASSERT_GE(r.path.partial_paths.size(), 2u);
  EXPECT_LT(direction_of(r.path.partial_paths[0]), 0.0);
  EXPECT_DOUBLE_EQ(r.path.partial_paths[0].points.back().longitudinal_velocity_mps, 0.0);
  EXPECT_DOUBLE_EQ(r.path.pairs_terminal_velocity_and_accel[0].velocity_mps, sc.parameters.backward_velocity);
  EXPECT_GT(r.evaluation_table.back().backward_distance_m, 0.0);
  EXPECT_GT(direction_of(r.path.partial_paths[1]), 0.0);
}

TEST(ScenarioSpecifics, ParallelSpotStopsBetweenTheArcsWithConsistentPairs) {
  const Scenario sc = load("parallel_spot");
  const PlanningResult r = StartPlanner(sc.vehicle, sc.parameters).plan(sc.request, StopCondition());
  ASSERT_TRUE(r.path.found);
  ASSERT_EQ(r.path.planner_type, PlannerType::kGeometric);
  ASSERT_EQ(r.path.partial_paths.size(), 2u);  // divide_pull_out_path: true
  const auto& arc1 = r.path.partial_paths[0].points;
  EXPECT_DOUBLE_EQ(arc1.back().longitudinal_velocity_mps, 0.0);
  double l1 = 0.0;
  for (std::size_t i = 1; i < arc1.size(); ++i)
    l1 += std::hypot(arc1[i].pose.x - arc1[i - 1].pose.x, arc1[i].pose.y - arc1[i - 1].pose.y);
  const auto pair1 = r.path.pairs_terminal_velocity_and_accel[0];
  // Reaching v at half of the arc with constant acceleration: a = v^2 / L1 (2 % for chords).
  EXPECT_NEAR(pair1.accel_mps2, pair1.velocity_mps * pair1.velocity_mps / l1, 0.02 * pair1.accel_mps2);
  EXPECT_GT(pair1.velocity_mps, 0.0);

  StartPlannerParameters single = sc.parameters;
  single.divide_pull_out_path = false;
  const PlanningResult r1 = StartPlanner(sc.vehicle, single).plan(sc.request, StopCondition());
  ASSERT_TRUE(r1.path.found);
  EXPECT_EQ(r1.path.partial_paths.size(), 1u);
}

}  // namespace
}  // namespace pullout
