#include "pullout/collision/object_checker.hpp"
#include "pullout/geometry/angle.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace pullout {
namespace {

// Vehicle rectangle 4 m long (3 ahead of base_link, 1 behind) and 2 m wide.
const Footprint kFootprint{3.0, 1.0, 1.0, 1.0};

Obstacle box(std::int64_t id, double cx, double cy, double hx, double hy) {
  return {id, {{cx + hx, cy + hy}, {cx - hx, cy + hy}, {cx - hx, cy - hy}, {cx + hx, cy - hy}}};
}

// FCL's GJK distance is iterative; 1e-6 m is far below anything a margin cares about.
constexpr double kGjkTolerance = 1e-6;

TEST(ObjectChecker, DistanceAheadMatchesTheGap) {
  const ObjectChecker checker(kFootprint, {box(3, 10.0, 0.0, 1.0, 1.0)});
  // Front of the vehicle at x = 3, rear of the box at x = 9.
  const auto c = checker.clearance({0.0, 0.0, 0.0});
  EXPECT_NEAR(c.distance, 6.0, kGjkTolerance);
  EXPECT_EQ(c.obstacle_id, 3);
}

TEST(ObjectChecker, DistanceToTheSideAndRotatedPose) {
  const ObjectChecker checker(kFootprint, {box(1, 0.0, 5.0, 2.0, 1.0)});
  // Left side of the vehicle at y = 1, bottom of the box at y = 4.
  EXPECT_NEAR(checker.clearance({0.0, 0.0, 0.0}).distance, 3.0, kGjkTolerance);
  // Turned by 90 degrees the front (3 m ahead of base_link) points at the box: gap 4 - 3 = 1.
  EXPECT_NEAR(checker.clearance({0.0, 0.0, kPi / 2}).distance, 1.0, kGjkTolerance);
}

TEST(ObjectChecker, CornerToCornerDistanceIsEuclidean) {
  const ObjectChecker checker(kFootprint, {box(1, 6.0, 5.0, 1.0, 1.0)});
  // Vehicle corner (3, 1), box corner (5, 4): sqrt(4 + 9).
  EXPECT_NEAR(checker.clearance({0.0, 0.0, 0.0}).distance, std::sqrt(13.0), kGjkTolerance);
}

TEST(ObjectChecker, OverlapIsDistanceZero) {
  const ObjectChecker checker(kFootprint, {box(1, 2.0, 0.0, 1.5, 0.5)});
  EXPECT_DOUBLE_EQ(checker.clearance({0.0, 0.0, 0.0}).distance, 0.0);
}

TEST(ObjectChecker, MarginDecidesTheHit) {
  const ObjectChecker checker(kFootprint, {box(9, 10.0, 0.0, 1.0, 1.0)});
  // Poses moving towards the box; the gap at pose i is 6 - i.
  std::vector<Pose2> poses;
  for (int i = 0; i <= 5; ++i) poses.push_back({static_cast<double>(i), 0.0, 0.0});
  EXPECT_FALSE(checker.first_hit(poses, 0.5).has_value());  // smallest gap is 1.0
  const auto hit = checker.first_hit(poses, 2.5);
  ASSERT_TRUE(hit.has_value());
  EXPECT_EQ(hit->pose_index, 4u);  // gap 2.0 < 2.5, pose 3 has gap 3.0
  EXPECT_EQ(hit->obstacle_id, 9);
  EXPECT_NEAR(hit->distance, 2.0, kGjkTolerance);
  // A margin equal to the gap is not a hit (collision means strictly closer than the margin).
  EXPECT_FALSE(checker.first_hit({{5.0, 0.0, 0.0}}, 1.0 - 1e-3).has_value());
}

TEST(ObjectChecker, NonConvexInputUsesItsHull) {
  // An L-shaped polygon; its hull reaches x = 8 at y = 0.
  const Obstacle l_shape{4, {{8, -1}, {12, -1}, {12, 3}, {11, 3}, {11, 0}, {8, 0}}};
  const ObjectChecker checker(kFootprint, {l_shape});
  EXPECT_NEAR(checker.clearance({0.0, 0.0, 0.0}).distance, 5.0, kGjkTolerance);
}

TEST(ObjectChecker, HorizonSkipsFarObstacles) {
  const ObjectChecker checker(kFootprint, {box(1, 50.0, 0.0, 1.0, 1.0)});
  EXPECT_TRUE(std::isinf(checker.clearance({0.0, 0.0, 0.0}, 5.0).distance));
  EXPECT_NEAR(checker.clearance({0.0, 0.0, 0.0}).distance, 46.0, kGjkTolerance);
}

TEST(Footprint, VehicleRectangleFromVehicleInfo) {
  const VehicleInfo v;
  const Footprint f = vehicle_footprint(v, 0.5);
  EXPECT_DOUBLE_EQ(f.front, 2.79 + 1.0 + 0.5);
  EXPECT_DOUBLE_EQ(f.rear, 1.1 + 0.5);
  EXPECT_DOUBLE_EQ(f.left, 0.82 + 0.128 + 0.5);
  const auto c = footprint_corners(f, {1.0, 2.0, kPi / 2});
  // Front-left corner of a vehicle facing +y: x decreases by `left`, y increases by `front`.
  EXPECT_NEAR(c[0].x(), 1.0 - f.left, 1e-12);
  EXPECT_NEAR(c[0].y(), 2.0 + f.front, 1e-12);
}

}  // namespace
}  // namespace pullout
