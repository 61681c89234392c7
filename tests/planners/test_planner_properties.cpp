// Properties of every planner on every scenario file: whatever a planner returns as found must be
// a path a vehicle can drive. The oracles here are independent of the planners' own checks: a
// plain polygon distance instead of FCL, and boundary sampling against the raw lane polygons
// instead of the lane world's outline.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <tuple>

#include "path_oracles.hpp"
#include "pullout/collision/footprint.hpp"
#include "pullout/config/scenario.hpp"
#include "pullout/model/names.hpp"
#include "pullout/pipeline/start_planner.hpp"

namespace pullout {
namespace {

using namespace oracle;  // NOLINT: the test's own helpers

const char* const kScenarios[] = {"straight_shoulder", "curved_road",       "parked_car_ahead",      "boxed_in",
                                  "parallel_spot",     "perpendicular_bay", "parallel_spot_reverse", "car_close_ahead",
                                  "full_search"};
const PlannerType kPlanners[] = {PlannerType::kShift, PlannerType::kGeometric, PlannerType::kClothoid};

Scenario load(const std::string& name) {
  return load_scenario(std::string(PULLOUT_SOURCE_DIR) + "/tests/scenarios/" + name + ".yaml");
}

// ---- the property test ----

class PlannerProperties : public ::testing::TestWithParam<std::tuple<const char*, PlannerType>> {};

TEST_P(PlannerProperties, FoundPathsAreDrivable) {
  const auto [name, planner_type] = GetParam();
  const Scenario sc = load(name);
  StartPlannerParameters params = sc.parameters;
  params.search_priority = {planner_type};
  const StartPlanner planner(sc.vehicle, params);
  const PlanningResult r = planner.plan(sc.request, StopCondition());
  if (r.outcome != PlanningResult::Outcome::kFound) {
    // Not finding a path is allowed; it must come as a stop path with reasons.
    EXPECT_FALSE(r.path.found);
    EXPECT_EQ(r.path.planner_type, PlannerType::kStop);
    EXPECT_FALSE(r.path.reasons.empty());
    for (const auto& p : r.path.partial_paths.at(0).points) EXPECT_DOUBLE_EQ(p.longitudinal_velocity_mps, 0.0);
    RecordProperty("found", "false");
    return;
  }
  const PullOutPath& path = r.path;
  ASSERT_TRUE(path.found);
  ASSERT_GE(path.partial_paths.size(), 1u);
  ASSERT_EQ(path.pairs_terminal_velocity_and_accel.size(), path.partial_paths.size()) << "one pair per segment";
  const double margin = r.evaluation_table.back().margin_m;
  ASSERT_EQ(r.evaluation_table.back().outcome, AttemptOutcome::kSuccess);

  // Starts at the vehicle.
  EXPECT_NEAR(path.partial_paths[0].points[0].pose.x, sc.request.ego_pose.x, 1e-9);
  EXPECT_NEAR(path.partial_paths[0].points[0].pose.y, sc.request.ego_pose.y, 1e-9);

  std::vector<Polygon> obstacles;
  for (const Object& o : sc.request.objects) obstacles.push_back(object_polygon(o));
  std::vector<Polygon> lanes;
  for (const Lane& l : sc.request.lanes) lanes.push_back(lane_polygon(l));
  const Footprint footprint = vehicle_footprint(sc.vehicle);
  const double expansion = planner_type == PlannerType::kGeometric ? params.lane_departure_margin
                                                                   : params.lane_departure_check_expansion_margin;
  const Footprint lane_footprint = vehicle_footprint(sc.vehicle, expansion);
  // Where the margin applies: up to the end pose, minus 10 m for shift
  // (shift_collision_check_distance_from_end); beyond that only contact is excluded.
  const double margin_until_end =
      planner_type == PlannerType::kShift ? params.shift_collision_check_distance_from_end : 0.0;
  bool passed_end = false;
  double forward_distance = 0.0;
  double end_distance = -1.0;
  // Distance from the forward start to the end pose, to know where the margin section ends.
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
      double clearance = std::numeric_limits<double>::infinity();
      for (const Polygon& o : obstacles)
        clearance = std::min(clearance, polygon_distance(footprint_polygon(footprint, pose), o));
      EXPECT_GT(clearance, 0.0) << "contact at segment " << k << " point " << i;
      if (dir > 0.0 && forward_distance <= end_distance + margin_until_end + 1e-9) {
        // 1e-3: FCL's GJK and this oracle agree to well below a millimetre.
        EXPECT_GE(clearance, margin - 1e-3) << "margin at segment " << k << " point " << i;
      }
      EXPECT_TRUE(footprint_in_lanes(lane_footprint, pose, lanes))
          << "lane departure at segment " << k << " point " << i;
      if (dir > 0.0 && std::hypot(pose.x - path.end_pose.x, pose.y - path.end_pose.y) < 1e-6) {
        passed_end = true;
        break;
      }
    }
  }

  // Curvature of the turns within the vehicle's limit (Menger curvature of consecutive points).
  const double k_max = 1.0 / sc.vehicle.min_turning_radius_m();
  for (const auto& seg : path.partial_paths) {
    for (std::size_t i = 1; i + 1 < seg.points.size(); ++i) {
      const Vec2 a = to_vec(seg.points[i - 1].pose);
      const Vec2 b = to_vec(seg.points[i].pose);
      const Vec2 c = to_vec(seg.points[i + 1].pose);
      const double cross = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
      const double denom = (b - a).norm() * (c - b).norm() * (c - a).norm();
      if (denom < 1e-12) continue;
      EXPECT_LE(std::abs(2.0 * cross / denom), k_max * 1.02) << "curvature at point " << i;
    }
  }
}

std::string param_name(const ::testing::TestParamInfo<PlannerProperties::ParamType>& info) {
  return std::string(std::get<0>(info.param)) + "_" + to_string(std::get<1>(info.param));
}

INSTANTIATE_TEST_SUITE_P(AllPlannersAllScenarios, PlannerProperties,
                         ::testing::Combine(::testing::ValuesIn(kScenarios), ::testing::ValuesIn(kPlanners)),
                         param_name);

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
const char* const kExpectationScenarios[] = {
    "straight_shoulder", "curved_road",           "parked_car_ahead", "boxed_in",    "parallel_spot",
    "perpendicular_bay", "parallel_spot_reverse", "car_close_ahead",  "full_search", "map_shoulder"};
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
