// The freespace pull-out end to end (scenario files through the pipeline): what it returns must
// be drivable. Oracles independent of the planner (tests/planners/path_oracles.hpp), none of
// them the planner's costmap or GridCollisionChecker: the footprint rectangle against the
// objects' polygons (separating axes), against the request's occupied grid cells (each an exact
// square) and inside the raw lane polygons, at every path point with the planner's margin and
// every 2 cm between the points with the bare body; Menger curvature of consecutive points.
#include "pullout/freespace/freespace_pull_out.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <limits>

#include "../planners/path_oracles.hpp"
#include "pullout/collision/footprint.hpp"
#include "pullout/collision/object_checker.hpp"
#include "pullout/config/scenario.hpp"
#include "pullout/geometry/angle.hpp"
#include "pullout/geometry/polygon.hpp"
#include "pullout/geometry/polyline.hpp"
#include "pullout/model/names.hpp"
#include "pullout/pipeline/start_planner.hpp"

namespace pullout {
namespace {

const char* const kFreespaceScenarios[] = {"freespace_boxed_in", "freespace_perpendicular_bay", "freespace_parking_lot",
                                           "freespace_kerb"};

Scenario load(const std::string& name) {
  return load_scenario(std::string(PULLOUT_SOURCE_DIR) + "/tests/scenarios/" + name + ".yaml");
}

int direction_of(const PathWithLaneId& seg) {
  for (const auto& p : seg.points) {
    if (p.longitudinal_velocity_mps > 0.0) return 1;
    if (p.longitudinal_velocity_mps < 0.0) return -1;
  }
  return 0;
}

// What every freespace path must be (the oracles in the file comment).
// `deadline_ms` is a generous bound, not a figure.
void expect_drivable_freespace_path(const Scenario& sc, double deadline_ms = 5000.0) {
  const StartPlanner planner(sc.vehicle, sc.parameters);
  const PlanningResult r = planner.plan(sc.request, StopCondition::after_ms(deadline_ms));
  std::string rows;
  for (const auto& a : r.evaluation_table) rows += describe(a) + "; ";
  ASSERT_EQ(r.outcome, PlanningResult::Outcome::kFound) << r.stop_reason << ": " << rows;
  const PullOutPath& path = r.path;
  EXPECT_EQ(path.planner_type, PlannerType::kFreespace);
  EXPECT_EQ(r.evaluation_table.back().planner, PlannerType::kFreespace);
  ASSERT_EQ(path.pairs_terminal_velocity_and_accel.size(), path.partial_paths.size());
  EXPECT_NEAR(path.partial_paths[0].points[0].pose.x, sc.request.ego_pose.x, 1e-9);
  EXPECT_NEAR(path.partial_paths[0].points[0].pose.y, sc.request.ego_pose.y, 1e-9);

  // What the planner promises: up to the end pose, the body grown by half of vehicle_shape_margin
  // on every side touches no object, no occupied grid cell and stays inside the lanes (its
  // costmap frees only cells entirely inside the lanes that no object touches). Between its
  // points and on the road after the end pose at least the body touches nothing.
  const FreespaceParameters& fp = sc.parameters.freespace_planner;
  std::vector<Polygon> objects;
  for (const Object& o : sc.request.objects) objects.push_back(object_polygon(o));
  std::vector<Polygon> lanes;
  for (const Lane& l : sc.request.lanes) lanes.push_back(oracle::lane_polygon(l));
  const OccupancyGrid* grid = sc.request.occupancy_grid ? &*sc.request.occupancy_grid : nullptr;
  const int threshold = fp.costmap_configs.obstacle_threshold;
  const Footprint body = vehicle_footprint(sc.vehicle);
  // The margin yields where the start has less room (freespace_pull_out.hpp): at least, every
  // side keeps half the margin or the start's smallest clearance (to the objects and the lane
  // edges, measured here) less the swing of a rear corner grown by half the margin on a full-lock
  // turn, less the search's sweep tolerance (a quarter of a cell) and 1 cm.
  const Footprint body0 = vehicle_footprint(sc.vehicle);
  double start_room = std::numeric_limits<double>::infinity();
  for (const Object& o : sc.request.objects) {
    start_room = std::min(
        start_room, oracle::polygon_distance(oracle::rectangle_at(body0, sc.request.ego_pose), object_polygon(o)));
  }
  if (!sc.request.lanes.empty()) {
    std::vector<Polygon> lane_polygons;
    for (const Lane& l : sc.request.lanes) lane_polygons.push_back(oracle::lane_polygon(l));
    for (double Footprint::*side : {&Footprint::front, &Footprint::rear, &Footprint::left, &Footprint::right}) {
      start_room = std::min(start_room, oracle::side_gap(body0, side, sc.request.ego_pose, lane_polygons, 2.0));
    }
  }
  const double half = 0.5 * fp.vehicle_shape_margin;
  const double turn = sc.vehicle.wheel_base_m / std::tan(sc.vehicle.max_steer_angle_rad * fp.max_turning_ratio);
  const double u = turn + std::min(body0.left, body0.right);
  const double swing = std::hypot(u, body0.rear + half) - u;
  const double promised =
      std::min(half, std::max(0.0, start_room - swing - 0.25 * fp.costmap_configs.resolution - 0.01));
  // 1 mm less than the promise: the oracle's rounding.
  const Footprint grown = vehicle_footprint(sc.vehicle, std::max(0.0, promised - 1e-3));
  const auto touches = [&](const Footprint& f, const Pose2& pose) {
    const Polygon rect = oracle::rectangle_at(f, pose);
    for (const Polygon& o : objects) {
      if (oracle::polygons_overlap(rect, o)) return true;
    }
    return grid != nullptr && oracle::overlaps_grid(*grid, threshold, rect);
  };
  const double k_max =
      1.0 / (sc.vehicle.wheel_base_m / std::tan(sc.vehicle.max_steer_angle_rad * fp.max_turning_ratio));

  int cusps = 0;
  for (std::size_t k = 0; k < path.partial_paths.size(); ++k) {
    const auto& seg = path.partial_paths[k];
    ASSERT_GE(seg.points.size(), 2u) << k;
    const int dir = direction_of(seg);
    ASSERT_NE(dir, 0) << k;
    for (const auto& p : seg.points) EXPECT_GE(p.longitudinal_velocity_mps * dir, 0.0) << "one direction per segment";
    const auto& pair = path.pairs_terminal_velocity_and_accel[k];
    EXPECT_EQ(pair.velocity_mps > 0.0, dir > 0) << k;
    EXPECT_GT(pair.accel_mps2 * dir, 0.0) << k;
    if (k + 1 < path.partial_paths.size()) {
      const auto& a = seg.points.back();
      const auto& b = path.partial_paths[k + 1].points.front();
      EXPECT_LT(std::hypot(a.pose.x - b.pose.x, a.pose.y - b.pose.y), 1e-9) << "join " << k;
      if (direction_of(path.partial_paths[k + 1]) != dir) {
        ++cusps;
        EXPECT_DOUBLE_EQ(a.longitudinal_velocity_mps, 0.0) << "stop at the cusp after " << k;
        EXPECT_NEAR(std::abs(pair.velocity_mps), fp.velocity, 1e-12);
        // v reached at half of the segment, stopped at its end: a = v^2 / L.
        EXPECT_NEAR(std::abs(pair.accel_mps2), fp.velocity * fp.velocity / polyline_length(seg), 1e-9);
      }
    }
    for (std::size_t i = 0; i < seg.points.size(); ++i) {
      const Pose2& pose = seg.points[i].pose;
      // Up to the end pose the grown footprint is clear of the costmap; on the road after it,
      // at least the body is clear of every object.
      const bool on_road_tail = k + 1 == path.partial_paths.size() && sc.request.occupancy_grid == std::nullopt &&
                                (pose.x - path.end_pose.x) * std::cos(path.end_pose.yaw) +
                                        (pose.y - path.end_pose.y) * std::sin(path.end_pose.yaw) >
                                    1e-6;
      if (!on_road_tail) {
        EXPECT_FALSE(touches(grown, pose)) << "margin, segment " << k << " point " << i;
        if (!lanes.empty()) {
          EXPECT_TRUE(oracle::footprint_in_lanes(grown, pose, lanes)) << "lanes, segment " << k << " point " << i;
        }
      }
    }
    for (const Pose2& pose : oracle::poses_along(seg, 0.02)) {
      ASSERT_FALSE(touches(body, pose)) << "contact, segment " << k << " at (" << pose.x << ", " << pose.y << ")";
    }
    for (std::size_t i = 1; i + 1 < seg.points.size(); ++i) {
      const double kappa = oracle::menger_curvature(to_vec(seg.points[i - 1].pose), to_vec(seg.points[i].pose),
                                                    to_vec(seg.points[i + 1].pose));
      EXPECT_LE(std::abs(kappa), k_max * 1.02) << "curvature, segment " << k << " point " << i;
    }
  }
  ::testing::Test::RecordProperty("cusps", cusps);
}

class FreespaceScenario : public ::testing::TestWithParam<const char*> {};

TEST_P(FreespaceScenario, FindsADrivablePath) { expect_drivable_freespace_path(load(GetParam())); }

// Autoware's freespace_planner_algorithm: rrtstar (seeded RRT*, OMPL) through the same pipeline
// and the same oracles.
TEST_P(FreespaceScenario, RrtStarFindsADrivablePath) {
  Scenario sc = load(GetParam());
  sc.parameters.freespace_planner.freespace_planner_algorithm = "rrtstar";
  // RRT*'s work is bounded by its iterations (rrt_star.hpp): these bounds, far above the time it
  // takes (a few hundred ms), only keep a loaded or sanitized run from cutting it short.
  sc.parameters.freespace_planner.time_limit = 60000.0;
  expect_drivable_freespace_path(sc, 60000.0);
}

// Deterministic through the pipeline: the same request planned twice, another rrtstar request in
// between, gives the same path point for point (the first version drew OMPL's process-wide seed).
TEST_P(FreespaceScenario, RrtStarGivesTheSamePathEveryTime) {
  Scenario sc = load(GetParam());
  sc.parameters.freespace_planner.freespace_planner_algorithm = "rrtstar";
  sc.parameters.freespace_planner.time_limit = 60000.0;
  const StartPlanner planner(sc.vehicle, sc.parameters);
  const PlanningResult first = planner.plan(sc.request, StopCondition::after_ms(60000));
  ASSERT_EQ(first.outcome, PlanningResult::Outcome::kFound) << first.stop_reason;
  Scenario other =
      load(std::string(GetParam()) == "freespace_parking_lot" ? "freespace_kerb" : "freespace_parking_lot");
  other.parameters.freespace_planner.freespace_planner_algorithm = "rrtstar";
  other.parameters.freespace_planner.time_limit = 60000.0;
  (void)StartPlanner(other.vehicle, other.parameters).plan(other.request, StopCondition::after_ms(60000));
  const PlanningResult again = planner.plan(sc.request, StopCondition::after_ms(60000));
  ASSERT_EQ(again.outcome, PlanningResult::Outcome::kFound) << again.stop_reason;
  ASSERT_EQ(first.path.partial_paths.size(), again.path.partial_paths.size());
  for (std::size_t k = 0; k < first.path.partial_paths.size(); ++k) {
    const auto& a = first.path.partial_paths[k].points;
    const auto& b = again.path.partial_paths[k].points;
    ASSERT_EQ(a.size(), b.size()) << k;
    for (std::size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(a[i].pose.x, b[i].pose.x) << k << " " << i;
      EXPECT_EQ(a[i].pose.y, b[i].pose.y) << k << " " << i;
      EXPECT_EQ(a[i].longitudinal_velocity_mps, b[i].longitudinal_velocity_mps) << k << " " << i;
    }
  }
}

// The objects rrtstar's costmap grows (freespace_pull_out.hpp): a 1 m square grown by 0.1 m is
// the 1.2 m square around it (the hull of the vertices moved by +-0.1), a superset of the points
// within 0.1 m.
TEST(FreespacePullOut, GrownObstaclesHoldEveryPointWithinTheGrowth) {
  const Polygon square{{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  const std::vector<Polygon> grown = grown_obstacles({square}, 0.1);
  ASSERT_EQ(grown.size(), 1u);
  EXPECT_NEAR(std::abs(signed_area(grown[0])), 1.2 * 1.2, 1e-12);
  for (int i = 0; i < 72; ++i) {
    const double a = i * kPi / 36;
    for (const Vec2& corner : square) {
      EXPECT_TRUE(point_in_polygon(grown[0], corner + 0.0999 * Vec2(std::cos(a), std::sin(a)))) << i;
    }
  }
  EXPECT_FALSE(point_in_polygon(grown[0], {1.15, 0.5}));
}

INSTANTIATE_TEST_SUITE_P(Scenarios, FreespaceScenario, ::testing::ValuesIn(kFreespaceScenarios));

TEST(FreespacePullOut, UnknownAlgorithmIsNamedByTheCoreValidation) {
  Scenario sc = load("freespace_parking_lot");
  sc.parameters.freespace_planner.freespace_planner_algorithm = "bitstar";
  const auto issues = validate_parameters(sc.parameters);
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_EQ(issues[0].name, "freespace_planner.freespace_planner_algorithm");
  EXPECT_NE(issues[0].problem.find("'bitstar'"), std::string::npos) << issues[0].problem;
}

// A grid-only request grows the vehicle by the shape margin where the start allows it, as one
// with lanes does (the header): at Autoware's default of 1.0 m the car nose-in in its bay of the
// lot was "start occupied" (the full margin reached the cars beside it), and is planned out now.
TEST(FreespacePullOut, AGridOnlyStartInABayKeepsTheMarginItHasRoomFor) {
  Scenario sc = load("freespace_parking_lot");
  sc.parameters.freespace_planner.vehicle_shape_margin = 1.0;
  sc.request.goal_pose = {25.0, 26.0, 0.0};  // clear of the east edge with the full margin
  const PlanningResult r = StartPlanner(sc.vehicle, sc.parameters).plan(sc.request, StopCondition());
  ASSERT_EQ(r.outcome, PlanningResult::Outcome::kFound) << r.stop_reason;
  EXPECT_EQ(r.path.planner_type, PlannerType::kFreespace);
}

TEST(FreespacePullOut, LanePlannersAloneCannotLeaveTheBoxedInSpot) {
  Scenario sc = load("freespace_boxed_in");
  sc.parameters.freespace_planner.enable_freespace_planner = false;
  const PlanningResult r = StartPlanner(sc.vehicle, sc.parameters).plan(sc.request, StopCondition());
  EXPECT_EQ(r.outcome, PlanningResult::Outcome::kNoPath);
}

TEST(FreespacePullOut, SplitsAtEveryCusp) {
  std::vector<Waypoint> w;
  for (int i = 0; i <= 4; ++i) w.push_back({{0.25 * i, 0.0, 0.0}, 1});
  for (int i = 1; i <= 4; ++i) w.push_back({{1.0 - 0.25 * i, 0.0, 0.0}, -1});
  for (int i = 1; i <= 2; ++i) w.push_back({{0.25 * i, 0.0, 0.0}, 1});
  const SplitPath s = split_at_cusps(w, 1.5);
  ASSERT_EQ(s.partial_paths.size(), 3u);
  EXPECT_EQ(s.directions, (std::vector<int>{1, -1, 1}));
  EXPECT_EQ(s.partial_paths[0].points.size(), 5u);
  EXPECT_EQ(s.partial_paths[1].points.size(), 5u);  // the cusp point is in both neighbours
  EXPECT_EQ(s.partial_paths[2].points.size(), 3u);
  EXPECT_DOUBLE_EQ(s.partial_paths[0].points[1].longitudinal_velocity_mps, 1.5);
  EXPECT_DOUBLE_EQ(s.partial_paths[1].points[1].longitudinal_velocity_mps, -1.5);
  for (const auto& p : s.partial_paths) EXPECT_DOUBLE_EQ(p.points.back().longitudinal_velocity_mps, 0.0);
  // 1 m at 1.5 m/s, stopping: a = v^2 / L.
  EXPECT_DOUBLE_EQ(s.pairs[0].velocity_mps, 1.5);
  EXPECT_DOUBLE_EQ(s.pairs[0].accel_mps2, 2.25);
  EXPECT_DOUBLE_EQ(s.pairs[1].velocity_mps, -1.5);
  EXPECT_DOUBLE_EQ(s.pairs[1].accel_mps2, -2.25);
}

// How long the stop takes is measured by bench/bench_planning (not asserted in a unit test).
TEST(FreespacePullOut, TinyDeadlineGivesATimeout) {
  const Scenario sc = load("freespace_perpendicular_bay");
  const StartPlanner planner(sc.vehicle, sc.parameters);
  const PlanningResult r = planner.plan(sc.request, StopCondition::after_ms(1.0));
  EXPECT_EQ(r.outcome, PlanningResult::Outcome::kNoPath);
  EXPECT_TRUE(r.timed_out);
}

// Defect: the freespace search dropped the caller's cancellation (it kept only the earlier of the
// two deadlines), so a superseded or shut-down search ran on up to time_limit. The work is bounded
// by the search's own counters, not by the clock.
TEST(FreespacePullOut, CancelledFlagStopsTheGoalSearchBeforeAnyExpansion) {
  Scenario sc = load("freespace_parking_lot");
  ASSERT_TRUE(sc.request.occupancy_grid.has_value());
  FreespaceParameters p = sc.parameters.freespace_planner;
  p.time_limit = 1e9;  // the own budget never ends it: only the flag can
  const Costmap costmap = freespace_costmap(p, &*sc.request.occupancy_grid, nullptr, {}, sc.request.ego_pose, 0.0);
  // Not cancelled: the search finds the path, with work done.
  std::atomic<bool> cancel{false};
  const StopCondition stop = StopCondition().with_cancel(&cancel);
  const FreespaceGoalResult running =
      plan_freespace_to_goal(costmap, sc.vehicle, p, sc.request.ego_pose, sc.request.goal_pose, stop);
  ASSERT_EQ(running.status, HybridAStarResult::Status::kSuccess);
  ASSERT_GT(running.expansions, 0u);
  // Cancelled: no expansion at all.
  cancel = true;
  const FreespaceGoalResult r =
      plan_freespace_to_goal(costmap, sc.vehicle, p, sc.request.ego_pose, sc.request.goal_pose, stop);
  EXPECT_EQ(r.status, HybridAStarResult::Status::kCancelled);
  EXPECT_EQ(r.stopped, StopReason::kCancelled);
  EXPECT_EQ(r.expansions, 0u);
  EXPECT_EQ(attempt_outcome(r.status), AttemptOutcome::kCancelled);
}

// The lane-based freespace pull-out, given the pipeline's context for the boxed-in spot.
TEST(FreespacePullOut, CancelledFlagStopsThePullOutSearch) {
  Scenario sc = load("freespace_boxed_in");
  sc.parameters.freespace_planner.time_limit = 1e9;
  const LaneWorld world(sc.request.lanes);
  const LaneChain road = world.chain_through(*world.nearest_lane(to_vec(sc.request.ego_pose), LaneSubtype::kRoad));
  std::vector<Obstacle> obstacles;
  std::vector<Polygon> polygons;
  for (const Object& o : sc.request.objects) {
    obstacles.push_back({o.id, object_polygon(o)});
    polygons.push_back(obstacles.back().polygon);
  }
  const ObjectChecker checker(vehicle_footprint(sc.vehicle), obstacles);
  const PlanningContext ctx{
      world,   road,     road, checker, sc.vehicle, sc.parameters, sc.request.goal_pose, 2.0, sc.request.ego_pose,
      nullptr, &polygons};
  std::atomic<bool> cancel{false};
  const StopCondition stop = StopCondition().with_cancel(&cancel);
  const PlannerCandidates running =
      FreespacePullOut(sc.parameters.freespace_planner).plan(ctx, sc.request.ego_pose, stop);
  ASSERT_EQ(running.candidates.size(), 1u);  // it finds one when not cancelled
  EXPECT_EQ(running.stopped, StopReason::kNone);
  cancel = true;
  const PlannerCandidates r = FreespacePullOut(sc.parameters.freespace_planner).plan(ctx, sc.request.ego_pose, stop);
  EXPECT_TRUE(r.candidates.empty());
  EXPECT_EQ(r.stopped, StopReason::kCancelled);
  EXPECT_EQ(select_candidate(r, 0.1).outcome, AttemptOutcome::kCancelled);
}

// Through the pipeline: a pure freespace request whose search is cancelled reports it in its row.
TEST(FreespacePullOut, CancelledGridOnlyRequestHasACancelledRow) {
  Scenario sc = load("freespace_parking_lot");
  sc.parameters.freespace_planner.time_limit = 1e9;
  std::atomic<bool> cancel{true};
  const PlanningResult r =
      StartPlanner(sc.vehicle, sc.parameters).plan(sc.request, StopCondition().with_cancel(&cancel));
  EXPECT_EQ(r.outcome, PlanningResult::Outcome::kNoPath);
  EXPECT_EQ(r.stopped, StopReason::kCancelled);
  EXPECT_FALSE(r.timed_out);
  ASSERT_EQ(r.evaluation_table.size(), 1u);
  EXPECT_EQ(r.evaluation_table[0].planner, PlannerType::kFreespace);
  EXPECT_EQ(r.evaluation_table[0].outcome, AttemptOutcome::kCancelled);
}

// freespace_planner.time_limit is the planner's own budget: it ends the freespace attempt
// (kTimeout, the budget named in the detail), not the planning, which is not timed out.
TEST(FreespacePullOut, OwnTimeLimitIsATimeoutRowNotAPlanningTimeout) {
  Scenario sc = load("freespace_boxed_in");
  sc.parameters.freespace_planner.time_limit = 0.0;
  const PlanningResult r = StartPlanner(sc.vehicle, sc.parameters).plan(sc.request, StopCondition());
  EXPECT_EQ(r.outcome, PlanningResult::Outcome::kNoPath);
  EXPECT_EQ(r.stopped, StopReason::kNone);
  EXPECT_FALSE(r.timed_out);
  ASSERT_FALSE(r.evaluation_table.empty());
  const PlannerAttempt& last = r.evaluation_table.back();
  EXPECT_EQ(last.planner, PlannerType::kFreespace);
  EXPECT_EQ(last.outcome, AttemptOutcome::kTimeout);
  EXPECT_NE(last.detail.find("budget"), std::string::npos) << last.detail;
}

TEST(FreespacePullOut, GridOnlyRequestsNeedTheFreespacePlanner) {
  Scenario sc = load("freespace_parking_lot");
  ASSERT_TRUE(sc.request.lanes.empty());
  ASSERT_TRUE(sc.request.occupancy_grid.has_value());
  sc.parameters.freespace_planner.enable_freespace_planner = false;
  const PlanningResult r = StartPlanner(sc.vehicle, sc.parameters).plan(sc.request, StopCondition());
  EXPECT_EQ(r.outcome, PlanningResult::Outcome::kRejected);
  ASSERT_FALSE(r.issues.empty());
  EXPECT_EQ(r.issues[0].field, "lanes");
}

// The freespace fallback from a backward start candidate (start_planner.hpp): the end poses of the
// current pose lie in road works, those of a candidate behind it do not.
TEST(FreespacePullOut, FallbackPlansFromABackwardStartCandidateWhenTheCurrentPoseFails) {
  const Scenario sc = load("freespace_blocked_ahead");
  {
    // The lane planner alone finds nothing; nor does freespace from the current pose alone.
    Scenario alone = sc;
    alone.parameters.freespace_planner.enable_freespace_planner = false;
    EXPECT_EQ(StartPlanner(alone.vehicle, alone.parameters).plan(alone.request, StopCondition()).outcome,
              PlanningResult::Outcome::kNoPath);
    alone = sc;
    alone.parameters.enable_back = false;
    const PlanningResult r = StartPlanner(alone.vehicle, alone.parameters).plan(alone.request, StopCondition());
    EXPECT_EQ(r.outcome, PlanningResult::Outcome::kNoPath);
    ASSERT_FALSE(r.evaluation_table.empty());
    EXPECT_EQ(r.evaluation_table.back().planner, PlannerType::kFreespace);
    EXPECT_EQ(r.evaluation_table.back().outcome, AttemptOutcome::kGoalInvalid) << describe(r.evaluation_table.back());
  }
  expect_drivable_freespace_path(sc);
  const PlanningResult r = StartPlanner(sc.vehicle, sc.parameters).plan(sc.request, StopCondition::after_ms(5000));
  ASSERT_EQ(r.outcome, PlanningResult::Outcome::kFound) << r.stop_reason;
  // Rows: freespace from the current pose failed (its end poses in the works), then succeeded
  // from a candidate behind.
  std::vector<const PlannerAttempt*> rows;
  for (const auto& a : r.evaluation_table) {
    if (a.planner == PlannerType::kFreespace) rows.push_back(&a);
  }
  ASSERT_GE(rows.size(), 2u);
  EXPECT_EQ(rows.front()->backward_distance_m, 0.0);
  EXPECT_EQ(rows.front()->outcome, AttemptOutcome::kGoalInvalid) << describe(*rows.front());
  EXPECT_EQ(rows.back()->outcome, AttemptOutcome::kSuccess);
  const double back = rows.back()->backward_distance_m;
  EXPECT_GT(back, 0.0);
  // The path: a straight reverse of that length from the current pose along the shoulder,
  // stopped at its end, then the freespace path; its end pose within the candidate's reach.
  const PathWithLaneId& reverse = r.path.partial_paths.front();
  ASSERT_GE(r.path.partial_paths.size(), 2u);
  for (std::size_t i = 0; i + 1 < reverse.points.size(); ++i)
    EXPECT_LT(reverse.points[i].longitudinal_velocity_mps, 0.0);
  EXPECT_EQ(reverse.points.back().longitudinal_velocity_mps, 0.0);
  for (const auto& p : reverse.points) EXPECT_NEAR(p.pose.y, sc.request.ego_pose.y, 1e-6);
  EXPECT_NEAR(reverse.points.back().pose.x, sc.request.ego_pose.x - back, 1e-6);
  EXPECT_NEAR(r.path.start_pose.x, sc.request.ego_pose.x - back, 1e-6);
  const FreespaceParameters& fp = sc.parameters.freespace_planner;
  EXPECT_LE(r.path.end_pose.x, sc.request.ego_pose.x - back + fp.end_pose_search_end_distance + 1e-6);
  EXPECT_LT(r.path.end_pose.x + sc.vehicle.length_m() - sc.vehicle.base_to_rear_m(), 60.0) << "short of the works";
}

// Listed in search_priority, freespace runs per start candidate in the search's order: from the
// candidate behind too (it answered "current pose only" before).
TEST(FreespacePullOut, ListedFreespacePlansFromABackwardStartCandidate) {
  Scenario sc = load("freespace_blocked_ahead");
  sc.parameters.search_priority = {PlannerType::kFreespace};
  sc.parameters.collision_check_margins = {0.1};
  const PlanningResult r = StartPlanner(sc.vehicle, sc.parameters).plan(sc.request, StopCondition::after_ms(5000));
  ASSERT_EQ(r.outcome, PlanningResult::Outcome::kFound) << r.stop_reason;
  EXPECT_EQ(r.path.planner_type, PlannerType::kFreespace);
  EXPECT_GT(r.evaluation_table.back().backward_distance_m, 0.0);
  EXPECT_LT(r.path.partial_paths.front().points.front().longitudinal_velocity_mps, 0.0);
}

TEST(FreespacePullOut, FreespaceInSearchPriorityRunsInItsPlace) {
  Scenario sc = load("freespace_boxed_in");
  sc.parameters.search_priority = {PlannerType::kFreespace};
  sc.parameters.collision_check_margins = {0.1};
  // The start candidates come from the lane-based search rules: keep the current pose one.
  sc.parameters.collision_check_margin_from_front_object = 0.0;
  sc.parameters.enable_back = false;
  const PlanningResult r = StartPlanner(sc.vehicle, sc.parameters).plan(sc.request, StopCondition::after_ms(5000));
  ASSERT_EQ(r.outcome, PlanningResult::Outcome::kFound) << r.stop_reason;
  EXPECT_EQ(r.path.planner_type, PlannerType::kFreespace);
  EXPECT_EQ(r.evaluation_table.back().outcome, AttemptOutcome::kSuccess);
}

}  // namespace
}  // namespace pullout
