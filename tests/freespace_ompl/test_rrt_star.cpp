// The RRT* freespace search (freespace_ompl/rrt_star.hpp) on its own: deterministic whatever ran
// before it, retried with the next seed and twice the iterations, bounded by attempts and by the
// stop condition, and its answer drivable. Oracles independent of the search: the footprint
// rectangle against the request's occupied grid cells (each an exact square,
// tests/planners/path_oracles.hpp) every 2 cm between the waypoints; iteration counts from the
// documented schedule (first_iterations * 2^k).
#include "pullout/freespace_ompl/rrt_star.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <thread>

#include "../planners/path_oracles.hpp"
#include "pullout/collision/footprint.hpp"
#include "pullout/config/scenario.hpp"
#include "pullout/freespace/freespace_pull_out.hpp"

namespace pullout {
namespace {

struct Problem {
  Scenario sc;
  Costmap costmap;
  Footprint footprint;
  HybridAStarConfig config;
};

Problem parking_lot() {
  Problem p;
  p.sc = load_scenario(std::string(PULLOUT_SOURCE_DIR) + "/tests/scenarios/freespace_parking_lot.yaml");
  const FreespaceParameters& fp = p.sc.parameters.freespace_planner;
  p.costmap = freespace_costmap(fp, &*p.sc.request.occupancy_grid, nullptr, {}, p.sc.request.ego_pose, 0.0);
  p.footprint = freespace_footprint(p.sc.vehicle, fp);
  p.config = freespace_search_config(p.sc.vehicle, fp);
  return p;
}

void expect_same(const HybridAStarResult& a, const HybridAStarResult& b) {
  ASSERT_EQ(a.waypoints.size(), b.waypoints.size());
  for (std::size_t i = 0; i < a.waypoints.size(); ++i) {
    EXPECT_EQ(a.waypoints[i].pose.x, b.waypoints[i].pose.x) << i;  // bit for bit
    EXPECT_EQ(a.waypoints[i].pose.y, b.waypoints[i].pose.y) << i;
    EXPECT_EQ(a.waypoints[i].pose.yaw, b.waypoints[i].pose.yaw) << i;
    EXPECT_EQ(a.waypoints[i].direction, b.waypoints[i].direction) << i;
  }
  EXPECT_EQ(a.expansions, b.expansions);
}

TEST(RrtStar, FindsADrivablePathShapedLikeHybridAStars) {
  const Problem p = parking_lot();
  const GridCollisionChecker checker(p.costmap, p.footprint);
  const Pose2 start = p.sc.request.ego_pose;
  const Pose2 goal = p.sc.request.goal_pose;
  const RrtStarResult r = run_rrt_star(checker, p.config, RrtStarConfig{}, start, goal, StopCondition::after_ms(20000));
  ASSERT_EQ(r.search.status, HybridAStarResult::Status::kSuccess);
  EXPECT_EQ(r.search.stopped, StopReason::kNone);
  const auto& w = r.search.waypoints;
  ASSERT_GE(w.size(), 2u);
  EXPECT_EQ(w.front().pose.x, start.x);
  EXPECT_EQ(w.front().pose.y, start.y);
  EXPECT_EQ(w.front().direction, w[1].direction);
  if (r.search.reached_exact_goal) {
    EXPECT_NEAR(w.back().pose.x, goal.x, 1e-9);
    EXPECT_NEAR(w.back().pose.y, goal.y, 1e-9);
  } else {
    EXPECT_LT(std::hypot(w.back().pose.x - goal.x, w.back().pose.y - goal.y), 0.05 + 1e-9);
  }
  // Waypoints at most waypoint_interval apart (chords of arcs: no longer than the arc), the
  // length the sum of the driven pieces, headings continuous.
  double chords = 0.0;
  for (std::size_t i = 1; i < w.size(); ++i) {
    const double d = std::hypot(w[i].pose.x - w[i - 1].pose.x, w[i].pose.y - w[i - 1].pose.y);
    EXPECT_LE(d, p.config.waypoint_interval + 1e-9) << i;
    EXPECT_LT(std::abs(w[i].pose.yaw - w[i - 1].pose.yaw), 0.5) << i;
    chords += d;
  }
  EXPECT_LE(chords, r.search.length + 1e-6);
  EXPECT_GT(chords, 0.99 * r.search.length);
  // The bare body touches no occupied cell of the request's grid, every 2 cm.
  const OccupancyGrid& grid = *p.sc.request.occupancy_grid;
  const int threshold = p.sc.parameters.freespace_planner.costmap_configs.obstacle_threshold;
  const Footprint body = vehicle_footprint(p.sc.vehicle);
  PathWithLaneId line;
  for (const Waypoint& x : w) line.points.push_back({x.pose, 0.0, {}});
  for (const Pose2& pose : oracle::poses_along(line, 0.02)) {
    ASSERT_FALSE(oracle::overlaps_grid(grid, threshold, oracle::rectangle_at(body, pose)))
        << "(" << pose.x << ", " << pose.y << ")";
  }
}

// The defect of the first version: OMPL's generators were seeded from the process-wide sequence,
// so the path (and whether one was found in the budget) depended on the run and on the tests
// before it. Now the same request gives the same path after another search, in another thread.
TEST(RrtStar, SamePathWhateverRanBefore) {
  const Problem p = parking_lot();
  const GridCollisionChecker checker(p.costmap, p.footprint);
  const Pose2 start = p.sc.request.ego_pose;
  const Pose2 goal = p.sc.request.goal_pose;
  const auto stop = [] { return StopCondition::after_ms(20000); };
  const RrtStarResult first = run_rrt_star(checker, p.config, RrtStarConfig{}, start, goal, stop());
  ASSERT_EQ(first.search.status, HybridAStarResult::Status::kSuccess);
  RrtStarConfig other;
  other.seed = 77;
  const RrtStarResult unrelated = run_rrt_star(checker, p.config, other, start, goal, stop());
  EXPECT_EQ(unrelated.search.status, HybridAStarResult::Status::kSuccess);
  RrtStarResult again;
  std::thread([&] { again = run_rrt_star(checker, p.config, RrtStarConfig{}, start, goal, stop()); }).join();
  expect_same(first.search, again.search);
  EXPECT_EQ(first.attempts, again.attempts);
  // The seed decides: another seed, another search.
  RrtStarConfig seed2;
  seed2.seed = kRrtStarSeed + 100;
  const RrtStarResult different = run_rrt_star(checker, p.config, seed2, start, goal, stop());
  EXPECT_NE(different.search.expansions, first.search.expansions);
}

TEST(RrtStar, RetriesWithTheNextSeedAndTwiceTheIterations) {
  const Problem p = parking_lot();
  const GridCollisionChecker checker(p.costmap, p.footprint);
  RrtStarConfig rrt;
  rrt.first_iterations = 2;  // far too few for the first attempts
  rrt.max_attempts = 20;
  const RrtStarResult r = run_rrt_star(checker, p.config, rrt, p.sc.request.ego_pose, p.sc.request.goal_pose,
                                       StopCondition::after_ms(20000));
  ASSERT_EQ(r.search.status, HybridAStarResult::Status::kSuccess);
  ASSERT_GT(r.attempts, 1);
  EXPECT_EQ(r.seed, kRrtStarSeed + static_cast<std::uint32_t>(r.attempts - 1));
  // Every failed attempt k ran its full 2 * 2^k iterations.
  std::size_t failed = 0;
  for (int k = 0; k + 1 < r.attempts; ++k) failed += std::size_t{2} << k;
  EXPECT_LE(r.iterations, std::size_t{2} << (r.attempts - 1));
  EXPECT_EQ(r.search.expansions, failed + r.iterations);
}

// A goal walled in: RRT* cannot prove there is no path; it gives up after max_attempts, having
// run exactly first_iterations * (1 + 2 + 4) iterations.
TEST(RrtStar, UnreachableGoalEndsAfterTheLastAttempt) {
  constexpr double kRes = 0.2;
  constexpr int kCells = 150;  // 30 m
  std::vector<std::uint8_t> occ(kCells * kCells, 0);
  Costmap costmap({0, 0, 0}, kRes, kCells, kCells, std::move(occ));
  // A closed 8 m x 6 m box of 0.4 m walls around (22, 15).
  costmap.add_obstacles({{{18, 12}, {26, 12}, {26, 12.4}, {18, 12.4}},
                         {{18, 17.6}, {26, 17.6}, {26, 18}, {18, 18}},
                         {{18, 12}, {18.4, 12}, {18.4, 18}, {18, 18}},
                         {{25.6, 12}, {26, 12}, {26, 18}, {25.6, 18}}});
  const GridCollisionChecker checker(costmap, {3.8, 1.0, 0.9, 0.9});
  HybridAStarConfig config;
  RrtStarConfig rrt;
  rrt.first_iterations = 50;
  rrt.max_attempts = 3;
  const RrtStarResult r = run_rrt_star(checker, config, rrt, {5, 5, 0}, {21, 15, 0}, StopCondition::after_ms(60000));
  EXPECT_EQ(r.search.status, HybridAStarResult::Status::kNoPath);
  EXPECT_EQ(r.search.stopped, StopReason::kNone);
  EXPECT_EQ(r.attempts, 3);
  EXPECT_EQ(r.search.expansions, 50u + 100u + 200u);
  EXPECT_TRUE(r.search.waypoints.empty());
}

TEST(RrtStar, StopsForTheDeadlineAndTheCancellation) {
  const Problem p = parking_lot();
  const GridCollisionChecker checker(p.costmap, p.footprint);
  const Pose2 start = p.sc.request.ego_pose;
  const Pose2 goal = p.sc.request.goal_pose;
  const HybridAStarResult expired = plan_rrt_star(checker, p.config, start, goal, StopCondition::after_ms(0.0));
  EXPECT_EQ(expired.status, HybridAStarResult::Status::kTimeout);
  EXPECT_EQ(expired.stopped, StopReason::kDeadline);
  EXPECT_EQ(expired.expansions, 0u);
  std::atomic<bool> cancel{true};
  const HybridAStarResult cancelled =
      plan_rrt_star(checker, p.config, start, goal, StopCondition().with_cancel(&cancel));
  EXPECT_EQ(cancelled.status, HybridAStarResult::Status::kCancelled);
  EXPECT_EQ(cancelled.stopped, StopReason::kCancelled);
  EXPECT_EQ(cancelled.expansions, 0u);
}

TEST(RrtStar, OccupiedStartOrGoalIsNamed) {
  const Problem p = parking_lot();
  const GridCollisionChecker checker(p.costmap, p.footprint);
  const Pose2 outside{-100.0, -100.0, 0.0};  // off the grid: occupied
  EXPECT_EQ(plan_rrt_star(checker, p.config, outside, p.sc.request.goal_pose, {}).status,
            HybridAStarResult::Status::kStartOccupied);
  EXPECT_EQ(plan_rrt_star(checker, p.config, p.sc.request.ego_pose, outside, {}).status,
            HybridAStarResult::Status::kGoalOccupied);
}

}  // namespace
}  // namespace pullout
