// Hybrid A* in tight spots where the plain search (0.5 m primitives on a 0.5 m lattice) gets
// stuck: parking into and out of a parallel slot half a metre longer than the car (TPCAP case 7's
// geometry: bench/RESULTS.md). The rescue searches (hybrid_astar.hpp, "Stuck searches") find the
// short moves between cusps. Every path is checked against an independent oracle: the footprint
// rectangle against the true obstacle boxes (separating axes, no costmap), every centimetre.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "../planners/path_oracles.hpp"
#include "pullout/freespace/costmap.hpp"
#include "pullout/freespace/hybrid_astar.hpp"
#include "pullout/geometry/angle.hpp"

namespace pullout {
namespace {

// TPCAP's vehicle: rear axle to front 3.76 m, to rear 0.929 m, width 1.942 m; turning radius
// 2.8 / tan(0.75) m.
const Footprint kCar{3.76, 0.929, 0.971, 0.971};
const double kRadius = 2.8 / std::tan(0.75);

struct Box {
  double x0, y0, x1, y1;
};

// The street: a kerb along y = 1, a wall at y = 14, a 5.19 m slot between two parked cars
// (0.2 m from the kerb) from x = 8 to x = 13.19.
constexpr double kSlotStart = 8.0;
constexpr double kSlotEnd = 13.19;
const std::vector<Box> kStreet{
    {0.0, 0.0, 30.0, 1.0},                 // kerb
    {0.0, 13.6, 30.0, 14.0},               // wall across the street
    {2.9, 1.2, kSlotStart, 3.1},           // car behind the slot
    {kSlotEnd, 1.2, kSlotEnd + 5.1, 3.1},  // car ahead of it
};
// In the slot, 0.25 m from either car, 0.2 m from the kerb.
const Pose2 kInSlot{kSlotStart + 0.25 + 0.929, 1.0 + 0.2 + 0.971, 0.0};
const Pose2 kInStreet{3.0, 7.0, 0.0};

Costmap street_map() {
  std::vector<Polygon> polygons;
  for (const Box& b : kStreet) polygons.push_back({{b.x0, b.y0}, {b.x1, b.y0}, {b.x1, b.y1}, {b.x0, b.y1}});
  Aabb extent;
  extent.extend({0.0, 0.0});
  extent.extend({30.0, 14.0});
  const Polygon all{{0.0, 0.0}, {30.0, 0.0}, {30.0, 14.0}, {0.0, 14.0}};
  return Costmap::from_polygons(extent, 0.1, {all}, {}, polygons);
}

// The oracle (tests/planners/path_oracles.hpp): the footprint's rectangle at `p` overlaps box `b`,
// touching not counted (separating axes: the box's two and the rectangle's two).
bool overlaps(const Pose2& p, const Box& b) {
  const Polygon box{{b.x0, b.y0}, {b.x1, b.y0}, {b.x1, b.y1}, {b.x0, b.y1}};
  return oracle::separating_gap(oracle::rectangle_at(kCar, p), box) < 0.0;
}

HybridAStarConfig config() {
  HybridAStarConfig c;
  c.turning_radius = kRadius;
  c.waypoint_interval = 0.01;
  return c;
}

// A found path, free under the oracle at every centimetre, within the turning radius, from the
// start to the exact goal.
void expect_free_and_drivable(const HybridAStarResult& r, const Pose2& start, const Pose2& goal) {
  ASSERT_EQ(r.status, HybridAStarResult::Status::kSuccess) << to_string(r.status);
  ASSERT_GE(r.waypoints.size(), 2u);
  EXPECT_NEAR(r.waypoints.front().pose.x, start.x, 1e-9);
  EXPECT_NEAR(r.waypoints.front().pose.y, start.y, 1e-9);
  if (r.reached_exact_goal) {
    EXPECT_NEAR(r.waypoints.back().pose.x, goal.x, 1e-6);
    EXPECT_NEAR(r.waypoints.back().pose.y, goal.y, 1e-6);
  }
  for (std::size_t i = 0; i < r.waypoints.size(); ++i) {
    const Pose2& p = r.waypoints[i].pose;
    for (const Box& b : kStreet) ASSERT_FALSE(overlaps(p, b)) << "waypoint " << i << " at " << p.x << ", " << p.y;
    if (i == 0) continue;
    const Pose2& q = r.waypoints[i - 1].pose;
    ASSERT_LE(std::hypot(p.x - q.x, p.y - q.y), 0.01 + 1e-9);
    if (i + 1 >= r.waypoints.size() || r.waypoints[i].direction != r.waypoints[i + 1].direction) continue;
    // Menger curvature within a cusp-free stretch (0 for coincident points).
    const Vec2 e{r.waypoints[i + 1].pose.x, r.waypoints[i + 1].pose.y};
    EXPECT_LE(std::abs(oracle::menger_curvature({q.x, q.y}, {p.x, p.y}, e)), 1.0 / kRadius * 1.01) << i;
  }
}

TEST(HybridAStarTightSpots, TheMapIsWhatTheTestsSay) {
  const Costmap m = street_map();
  const GridCollisionChecker checker(m, kCar);
  EXPECT_FALSE(checker.collides(kInSlot));
  EXPECT_FALSE(checker.collides(kInStreet));
  for (const Box& b : kStreet) EXPECT_FALSE(overlaps(kInSlot, b));
  // Half a metre to spare along the slot: 0.6 m forwards collides.
  EXPECT_TRUE(checker.collides({kInSlot.x + 0.6, kInSlot.y, 0.0}));
  EXPECT_TRUE(overlaps({kInSlot.x + 0.6, kInSlot.y, 0.0}, kStreet[3]));
}

TEST(HybridAStarTightSpots, ParallelParkingIntoASlotHalfAMetreLongerThanTheCar) {
  const Costmap m = street_map();
  const GridCollisionChecker checker(m, kCar);
  const HybridAStar planner(checker, config());
  const HybridAStarResult r = planner.plan(kInStreet, kInSlot, StopCondition::after_ms(30000));
  expect_free_and_drivable(r, kInStreet, kInSlot);
  EXPECT_TRUE(r.reached_exact_goal);
  EXPECT_TRUE(r.found_from_goal);  // the goal side: out of the slot, backwards in time
}

TEST(HybridAStarTightSpots, PullingOutOfASlotHalfAMetreLongerThanTheCar) {
  // The goal: in the street, heading on.
  const Pose2 goal{22.0, 7.0, 0.0};
  const Costmap m = street_map();
  const GridCollisionChecker checker(m, kCar);
  const HybridAStar planner(checker, config());
  const HybridAStarResult r = planner.plan(kInSlot, goal, StopCondition::after_ms(30000));
  expect_free_and_drivable(r, kInSlot, goal);
}

TEST(HybridAStarTightSpots, ThePlainSearchAloneIsStuckThere) {
  // Why the rescue exists: without it (min_primitive_length 0) neither direction is found.
  const Costmap m = street_map();
  const GridCollisionChecker checker(m, kCar);
  HybridAStarConfig c = config();
  c.min_primitive_length = 0.0;
  c.max_nodes = 200000;
  const HybridAStar planner(checker, c);
  EXPECT_NE(planner.plan(kInStreet, kInSlot, StopCondition::after_ms(30000)).status,
            HybridAStarResult::Status::kSuccess);
  EXPECT_NE(planner.plan(kInSlot, {22.0, 7.0, 0.0}, StopCondition::after_ms(30000)).status,
            HybridAStarResult::Status::kSuccess);
}

}  // namespace
}  // namespace pullout
