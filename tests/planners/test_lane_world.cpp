// The lane world's spatial index over any coordinates: negative cells, points far away, lanes
// whose extent is far larger than what they hold. Oracle: the lanes are axis-aligned rectangles,
// so whether a point or footprint is inside is read off the numbers.
#include "pullout/lanes/lane_world.hpp"

#include <gtest/gtest.h>

#include <array>

#include "test_world.hpp"

namespace pullout {
namespace {

TEST(IdenticalLanes, EqualCopiesAreIdenticalAndEveryFieldCounts) {
  const std::vector<Lane> lanes = test::straight_shoulder_request().lanes;
  EXPECT_TRUE(identical_lanes(lanes, lanes));
  EXPECT_TRUE(identical_lanes(std::vector<Lane>(lanes), lanes));
  EXPECT_FALSE(identical_lanes(lanes, {lanes.front()}));

  std::vector<Lane> other = lanes;
  other[1].right_bound.back().y += 1e-9;
  EXPECT_FALSE(identical_lanes(lanes, other));
  other = lanes;
  other[0].id = 7;
  EXPECT_FALSE(identical_lanes(lanes, other));
  other = lanes;
  other[1].subtype = LaneSubtype::kRoad;
  EXPECT_FALSE(identical_lanes(lanes, other));
  other = lanes;
  other[0].speed_limit_mps += 1.0;
  EXPECT_FALSE(identical_lanes(lanes, other));
  other = lanes;
  other[0].centerline = {{0.0, 0.0}, {100.0, 0.0}};
  EXPECT_FALSE(identical_lanes(lanes, other));
}

TEST(IdenticalLanes, NegativeZeroIsNotZero) {
  // Equal as numbers, but atan2 tells them apart: a world built from one is not proven the other's.
  std::vector<Lane> lanes = test::straight_shoulder_request().lanes;
  lanes[0].left_bound.front().x = 0.0;
  std::vector<Lane> other = lanes;
  other[0].left_bound.front().x = -0.0;
  ASSERT_EQ(lanes[0].left_bound.front().x, other[0].left_bound.front().x);
  EXPECT_FALSE(identical_lanes(lanes, other));
}

TEST(LaneWorld, AChainIsBuiltOnceAndIsTheChainOfItsLanes) {
  // Two road lanes in a row and a shoulder beside the first.
  const LaneWorld world({test::straight_lane(1, LaneSubtype::kRoad, 0, 50, -1.75, 1.75),
                         test::straight_lane(2, LaneSubtype::kRoad, 50, 100, -1.75, 1.75),
                         test::straight_lane(3, LaneSubtype::kRoadShoulder, 0, 50, 1.75, 4.75)});
  const LaneChain& through_second = world.chain_through(1);
  EXPECT_EQ(through_second.lanes, (std::vector<std::size_t>{0, 1}));
  const LaneChain built = world.chain_of({0, 1});
  EXPECT_EQ(through_second.centerline.points(), built.centerline.points());
  EXPECT_EQ(through_second.lane_end_s, built.lane_end_s);
  // The same chain object for the same seed; another seed has its own.
  EXPECT_EQ(&world.chain_through(1), &through_second);
  EXPECT_EQ(world.chain_through(0).lanes, through_second.lanes);
  EXPECT_NE(&world.chain_through(0), &through_second);
  EXPECT_EQ(world.chain_through(2).lanes, (std::vector<std::size_t>{2}));
}

TEST(LaneWorld, NegativeCoordinatesAreIndexed) {
  // Cells with negative indices (their hash key was once a shift of a negative number).
  const LaneWorld world({test::straight_lane(1, LaneSubtype::kRoad, -100, -50, -10, -6.5),
                         test::straight_lane(2, LaneSubtype::kRoad, 50, 100, 6.5, 10)});
  EXPECT_EQ(world.lanes_containing({-75.0, -8.0}), std::vector<std::size_t>{0});
  EXPECT_EQ(world.lanes_containing({75.0, 8.0}), std::vector<std::size_t>{1});
  EXPECT_TRUE(world.lanes_containing({-75.0, 8.0}).empty());
  EXPECT_TRUE(world.lanes_containing({75.0, -8.0}).empty());
  EXPECT_TRUE(world.lanes_containing({-49.0, -8.0}).empty());
}

TEST(LaneWorld, FarAwayPointsAreOutside) {
  const LaneWorld world({test::straight_lane(1, LaneSubtype::kRoad, 0, 100, -1.75, 1.75)});
  for (const Vec2& p : {Vec2{1e300, 0.0}, Vec2{-1e300, 0.0}, Vec2{50.0, 1e300}, Vec2{1e300, -1e300}}) {
    EXPECT_FALSE(world.contains(p)) << p.transpose();
  }
  const std::array<Vec2, 4> far = {Vec2{1e300, -1.0}, Vec2{1e300, -1.0}, Vec2{1e300, 1.0}, Vec2{1e300, 1.0}};
  EXPECT_FALSE(world.footprint_inside(far));
  EXPECT_TRUE(world.contains({50.0, 0.0}));
}

TEST(LaneWorld, HugeLanesAreBuiltAndQueried) {
  // Two roads 1e20 m long with no centerline (the derived one would need 2e20 samples at 0.5 m)
  // and a gap of 3.25 m between them, and an ordinary lane. Neither the sampling nor the index
  // grows with the extent.
  const LaneWorld world({test::straight_lane(1, LaneSubtype::kRoad, 0, 1e20, -1.75, 1.75),
                         test::straight_lane(2, LaneSubtype::kRoad, 0, 100, 1.75, 5.25),
                         test::straight_lane(3, LaneSubtype::kRoad, 0, 1e20, -8.5, -5.0)});
  EXPECT_LE(world.lanes()[0].centerline.size(), 100001u);
  EXPECT_GE(world.lanes()[0].centerline.size(), 2u);
  EXPECT_DOUBLE_EQ(world.lanes()[0].centerline.points().back().x(), 1e20);
  EXPECT_EQ(world.lanes_containing({5e19, 0.0}), std::vector<std::size_t>{0});
  EXPECT_EQ(world.lanes_containing({50.0, 3.0}), std::vector<std::size_t>{1});
  EXPECT_EQ(world.lanes_containing({1e6, -6.0}), std::vector<std::size_t>{2});
  EXPECT_TRUE(world.lanes_containing({50.0, -3.0}).empty());
  // A car-sized footprint inside the huge road; one with corners beyond its right bound.
  EXPECT_TRUE(world.footprint_inside({Vec2{1000.0, -1.0}, Vec2{1004.0, -1.0}, Vec2{1004.0, 1.0}, Vec2{1000.0, 1.0}}));
  EXPECT_FALSE(
      world.footprint_inside({Vec2{1000.0, -3.5}, Vec2{1004.0, -3.5}, Vec2{1004.0, -0.5}, Vec2{1000.0, -0.5}}));
  // Every corner inside a lane (two on each huge road), but the sides cross the gap between them:
  // only the two bounds 1e20 m long are crossed.
  EXPECT_FALSE(world.footprint_inside({Vec2{10.0, -6.0}, Vec2{14.0, -6.0}, Vec2{14.0, 0.0}, Vec2{10.0, 0.0}}));
}

}  // namespace
}  // namespace pullout
