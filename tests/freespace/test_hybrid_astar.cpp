// Hybrid A* on small costmaps built in code: properties of what it returns (collision-free,
// curvature, direction bookkeeping), its typed failures, and the deadline.
#include "pullout/freespace/hybrid_astar.hpp"
#include "pullout/geometry/angle.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace pullout {
namespace {

constexpr double kRes = 0.2;

// A w x h metre map with a wall of cells around it and the given occupied boxes (map frame).
Costmap walled_map(double w, double h, const std::vector<Polygon>& boxes = {}) {
  const int cw = static_cast<int>(std::round(w / kRes));
  const int ch = static_cast<int>(std::round(h / kRes));
  std::vector<std::uint8_t> occ(static_cast<std::size_t>(cw * ch), 0);
  for (int i = 0; i < cw; ++i) occ[static_cast<std::size_t>(i)] = occ[static_cast<std::size_t>((ch - 1) * cw + i)] = 1;
  for (int j = 0; j < ch; ++j)
    occ[static_cast<std::size_t>(j * cw)] = occ[static_cast<std::size_t>(j * cw + cw - 1)] = 1;
  Costmap m({}, kRes, cw, ch, std::move(occ));
  m.add_obstacles(boxes);
  return m;
}

Polygon box(double x0, double y0, double x1, double y1) { return {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}; }

const Footprint kCar{3.79, 1.1, 0.95, 0.95};

HybridAStarConfig config() {
  HybridAStarConfig c;
  c.turning_radius = 5.2;
  return c;
}

// The properties every found path has.
void expect_drivable(const GridCollisionChecker& checker, const HybridAStarResult& r, const Pose2& start,
                     double turning_radius) {
  ASSERT_EQ(r.status, HybridAStarResult::Status::kSuccess);
  ASSERT_GE(r.waypoints.size(), 2u);
  EXPECT_NEAR(r.waypoints.front().pose.x, start.x, 1e-9);
  EXPECT_NEAR(r.waypoints.front().pose.y, start.y, 1e-9);
  for (const Waypoint& w : r.waypoints) {
    EXPECT_FALSE(checker.collides(w.pose)) << w.pose.x << ", " << w.pose.y;
    EXPECT_TRUE(w.direction == 1 || w.direction == -1);
  }
  for (std::size_t i = 1; i + 1 < r.waypoints.size(); ++i) {
    const Vec2 a{r.waypoints[i - 1].pose.x, r.waypoints[i - 1].pose.y};
    const Vec2 b{r.waypoints[i].pose.x, r.waypoints[i].pose.y};
    const Vec2 c{r.waypoints[i + 1].pose.x, r.waypoints[i + 1].pose.y};
    EXPECT_LE((b - a).norm(), 0.25 + 1e-9);
    // Menger curvature within a cusp-free stretch.
    if (r.waypoints[i].direction != r.waypoints[i + 1].direction) continue;
    const double cross = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
    const double denom = (b - a).norm() * (c - b).norm() * (c - a).norm();
    if (denom > 1e-12) {
      EXPECT_LE(std::abs(2.0 * cross / denom), 1.0 / turning_radius * 1.001) << i;
    }
  }
}

TEST(HybridAStar, OpenLotReachesTheExactGoal) {
  const Costmap m = walled_map(30, 30);
  const GridCollisionChecker checker(m, kCar);
  const HybridAStar planner(checker, config());
  const Pose2 start{6, 6, 0};
  const Pose2 goal{22, 22, kPi / 2};
  const HybridAStarResult r = planner.plan(start, goal, StopCondition::after_ms(2000));
  expect_drivable(checker, r, start, 5.2);
  EXPECT_TRUE(r.reached_exact_goal);
  EXPECT_NEAR(r.waypoints.back().pose.x, goal.x, 1e-9);
  EXPECT_NEAR(r.waypoints.back().pose.y, goal.y, 1e-9);
}

TEST(HybridAStar, GoalBehindAWallIsReachedAroundIt) {
  // A wall across the middle with a gap at the top: the path must go through the gap.
  const Costmap m = walled_map(30, 30, {box(14, 0, 15, 22)});
  const GridCollisionChecker checker(m, kCar);
  const HybridAStar planner(checker, config());
  const Pose2 start{5, 5, 0};
  const Pose2 goal{25, 5, 0};
  const HybridAStarResult r = planner.plan(start, goal, StopCondition::after_ms(3000));
  expect_drivable(checker, r, start, 5.2);
  double max_y = 0.0;
  for (const auto& w : r.waypoints) max_y = std::max(max_y, w.pose.y);
  EXPECT_GT(max_y, 22.0);
}

// turning_heuristic_weight changes the order of the search, never what a path must be: around the
// wall (the charge is added beyond the Reeds-Shepp range, 20.8 m here, so the start and most of the
// way lie in its reach) and into a bay behind a row of cars.
TEST(HybridAStar, PathsWithTheTurningChargeAreDrivable) {
  HybridAStarConfig c = config();
  c.turning_heuristic_weight = 1.0;
  {
    const Costmap m = walled_map(30, 30, {box(14, 0, 15, 22)});
    const GridCollisionChecker checker(m, kCar);
    const HybridAStar planner(checker, c);
    const Pose2 start{5, 5, 0};
    const HybridAStarResult r = planner.plan(start, {25, 5, 0}, StopCondition::after_ms(3000));
    expect_drivable(checker, r, start, 5.2);
    double max_y = 0.0;
    for (const auto& w : r.waypoints) max_y = std::max(max_y, w.pose.y);
    EXPECT_GT(max_y, 22.0);
  }
  {
    // A 60 m lot: a row of cars along the south wall, the goal past its far end nose out (reversed
    // into), the start 44 m away facing away from it (the charge's case: it must turn round).
    std::vector<Polygon> cars;
    for (double x = 4.0; x < 50.0; x += 2.7) cars.push_back(box(x, 0.2, x + 1.9, 5.0));
    const Costmap m = walled_map(60, 20, cars);
    const GridCollisionChecker checker(m, kCar);
    const HybridAStar planner(checker, c);
    const Pose2 start{10, 12, kPi};
    const Pose2 goal{53.5, 1.5, kPi / 2};
    const HybridAStarResult r = planner.plan(start, goal, StopCondition::after_ms(5000));
    expect_drivable(checker, r, start, 5.2);
    EXPECT_TRUE(r.reached_exact_goal || r.found_from_goal);
  }
}

TEST(HybridAStar, TurningAroundInANarrowCorridorNeedsReversing) {
  // A 7 m wide corridor: a U-turn needs at least one direction change.
  const Costmap m = walled_map(40, 7.4);
  const GridCollisionChecker checker(m, kCar);
  const HybridAStar planner(checker, config());
  const Pose2 start{20, 3.7, 0};
  const Pose2 goal{20, 3.7, kPi};
  const HybridAStarResult r = planner.plan(start, goal, StopCondition::after_ms(3000));
  expect_drivable(checker, r, start, 5.2);
  int changes = 0;
  for (std::size_t i = 1; i < r.waypoints.size(); ++i) {
    changes += r.waypoints[i].direction != r.waypoints[i - 1].direction ? 1 : 0;
  }
  EXPECT_GE(changes, 1);
}

TEST(HybridAStar, EveryPointOfThePathIsFreeNotOnlyTheTestedPoses) {
  // Reversing into a 2.5 m bay between two parked cars (0.3 m each side of a 1.9 m car): the
  // motion between tested poses is covered too. Waypoints every centimetre, each tested exactly.
  const Costmap m = walled_map(24, 16, {box(6.5, 0.2, 8.4, 5.0), box(10.9, 0.2, 12.8, 5.0)});
  const GridCollisionChecker checker(m, kCar);
  HybridAStarConfig c = config();
  c.waypoint_interval = 0.01;
  const HybridAStar planner(checker, c);
  const Pose2 start{4, 10, 0};
  const Pose2 goal{9.65, 1.5, kPi / 2};  // rear axle in the bay, nose to the aisle
  const HybridAStarResult r = planner.plan(start, goal, StopCondition::after_ms(5000));
  ASSERT_EQ(r.status, HybridAStarResult::Status::kSuccess);
  ASSERT_GT(r.waypoints.size(), 500u);
  for (std::size_t i = 0; i < r.waypoints.size(); ++i) {
    ASSERT_FALSE(checker.collides(r.waypoints[i].pose)) << "waypoint " << i << " of " << r.waypoints.size();
    if (i > 0) {
      const Pose2& a = r.waypoints[i - 1].pose;
      const Pose2& b = r.waypoints[i].pose;
      ASSERT_LE(std::hypot(b.x - a.x, b.y - a.y), 0.01 + 1e-9);
    }
  }
}

TEST(HybridAStar, TypedFailures) {
  const Costmap m = walled_map(30, 30, {box(14, 0, 15, 30)});  // a wall with no gap
  const GridCollisionChecker checker(m, kCar);
  const HybridAStar planner(checker, config());
  EXPECT_EQ(planner.plan({14, 10, 0}, {25, 10, 0}, StopCondition()).status, HybridAStarResult::Status::kStartOccupied);
  EXPECT_EQ(planner.plan({5, 10, 0}, {14.5, 20, 0}, StopCondition()).status, HybridAStarResult::Status::kGoalOccupied);
  EXPECT_EQ(planner.plan({5, 10, 0}, {-50, 10, 0}, StopCondition()).status, HybridAStarResult::Status::kGoalOccupied);
  EXPECT_EQ(planner.plan({5, 10, 0}, {25, 10, 0}, StopCondition::after_ms(5000)).status,
            HybridAStarResult::Status::kNoPath);
}

// How promptly the search stops is a figure for bench/bench_planning (BM_Plan_FreespaceTinyDeadline),
// not a unit-test assertion.
TEST(HybridAStar, DeadlineGivesATimeout) {
  // A large lot with the goal in a room whose door (1.7 m) is too narrow for the car but not for
  // the heuristic's rear-axle disc: the search would exhaust the whole lot.
  const Costmap m = walled_map(100, 100, {box(80, 80, 81, 88), box(80, 89.7, 81, 100), box(80, 80, 100, 81)});
  const GridCollisionChecker checker(m, kCar);
  const HybridAStar planner(checker, config());
  const HybridAStarResult r = planner.plan({10, 10, 0}, {90, 90, 0}, StopCondition::after_ms(5));
  EXPECT_EQ(r.status, HybridAStarResult::Status::kTimeout);
  EXPECT_EQ(planner.plan({10, 10, 0}, {90, 90, 0}, StopCondition::after_ms(0)).status,
            HybridAStarResult::Status::kTimeout);
}

}  // namespace
}  // namespace pullout
