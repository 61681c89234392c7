// Geometry of the CLI's pictures: clipping to the view box and what the main view frames.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "svg_geometry.hpp"

namespace pullout::cli {
namespace {

// Shoelace area of a polygon [m^2].
double area(const std::vector<Point2>& polygon) {
  double twice = 0.0;
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const Point2& a = polygon[i];
    const Point2& b = polygon[(i + 1) % polygon.size()];
    twice += a.x * b.y - b.x * a.y;
  }
  return std::abs(twice) / 2.0;
}

TEST(Box, GrowsIntersectsAndHoldsAMinimumSize) {
  Box b;
  EXPECT_TRUE(b.empty());
  b.add({1.0, 2.0});
  b.add({std::nan(""), 50.0});  // skipped
  b.add({3.0, -1.0});
  EXPECT_DOUBLE_EQ(b.width(), 2.0);
  EXPECT_DOUBLE_EQ(b.height(), 3.0);
  const Box big = b.at_least(10.0, 1.0);
  EXPECT_DOUBLE_EQ(big.min_x, -3.0);  // grown about the centre x = 2
  EXPECT_DOUBLE_EQ(big.max_x, 7.0);
  EXPECT_DOUBLE_EQ(big.height(), 3.0);  // already taller than 1 m
  EXPECT_TRUE(big.contains(b));
  EXPECT_FALSE(b.contains(big));
  EXPECT_TRUE(Box(0, 0, 1, 1).intersection(Box(2, 2, 3, 3)).empty());
  EXPECT_TRUE(Box(0, 0, 1, 1).meets(Box(1, 1, 3, 3)));  // touching counts
}

TEST(ClipPolygon, KeepsWhatIsInsideTheBox) {
  const Box box{0.0, 0.0, 10.0, 10.0};
  const std::vector<Point2> inside{{1, 1}, {2, 1}, {2, 2}};
  const auto same = clip_polygon(inside, box);
  ASSERT_EQ(same.size(), 3u);
  EXPECT_DOUBLE_EQ(same[1].x, 2.0);
  EXPECT_TRUE(clip_polygon({{11, 11}, {12, 11}, {12, 12}}, box).empty());
  // A 4 x 4 square centred on the corner (10, 10): a quarter (2 x 2) is inside.
  const auto corner = clip_polygon({{8, 8}, {12, 8}, {12, 12}, {8, 12}}, box);
  EXPECT_NEAR(area(corner), 4.0, 1e-12);
  for (const Point2& p : corner) EXPECT_TRUE(box.contains(p)) << p.x << "," << p.y;
  // A lane 150 m long through a 10 m box: a 10 x 3.5 m rectangle.
  const auto lane = clip_polygon({{-70, 1.75}, {80, 1.75}, {80, -1.75}, {-70, -1.75}}, Box{0, -5, 10, 5});
  EXPECT_NEAR(area(lane), 35.0, 1e-9);
  // A box that holds none of the polygon's corners but cuts through it (the polygon covers it).
  const auto covered = clip_polygon({{-5, -5}, {15, -5}, {15, 15}, {-5, 15}}, box);
  EXPECT_NEAR(area(covered), 100.0, 1e-9);
}

TEST(ClipPolyline, CutsAtTheEdgesIntoRuns) {
  const Box box{0.0, 0.0, 10.0, 10.0};
  // In from the left at y = 5, out at the right: one run from (0, 5) to (10, 5) through (5, 5).
  const auto across = clip_polyline({{-5, 5}, {5, 5}, {15, 5}}, box);
  ASSERT_EQ(across.size(), 1u);
  ASSERT_EQ(across[0].size(), 3u);
  EXPECT_DOUBLE_EQ(across[0][0].x, 0.0);
  EXPECT_DOUBLE_EQ(across[0][1].x, 5.0);
  EXPECT_DOUBLE_EQ(across[0][2].x, 10.0);
  // Out and back in: two runs. The diagonal from (5, 5) to (15, 15) leaves at (10, 10).
  const auto twice = clip_polyline({{5, 5}, {15, 15}, {15, 5}, {5, 2}}, box);
  ASSERT_EQ(twice.size(), 2u);
  EXPECT_NEAR(twice[0][1].x, 10.0, 1e-12);
  EXPECT_NEAR(twice[0][1].y, 10.0, 1e-12);
  // (15, 5) -> (5, 2): enters at x = 10, y = 5 - 3 * 0.5 = 3.5.
  EXPECT_NEAR(twice[1][0].x, 10.0, 1e-12);
  EXPECT_NEAR(twice[1][0].y, 3.5, 1e-12);
  EXPECT_DOUBLE_EQ(twice[1][1].y, 2.0);
  // Wholly outside, and a non-finite point splitting a line inside.
  EXPECT_TRUE(clip_polyline({{-5, -5}, {-1, 20}}, box).empty());
  const auto split = clip_polyline({{1, 1}, {2, 2}, {std::nan(""), 3}, {4, 4}, {5, 5}}, box);
  EXPECT_EQ(split.size(), 2u);
}

PathWithLaneId straight(double x0, double x1, double y, double v, int n) {
  PathWithLaneId seg;
  for (int i = 0; i <= n; ++i) seg.points.push_back({{x0 + (x1 - x0) * i / n, y, 0.0}, i == n ? 0.0 : v, {}});
  return seg;
}

TEST(ManoeuvrePoses, StopAtTheEndPoseOfTheLastSegment) {
  PullOutPath path;
  path.found = true;
  path.partial_paths = {straight(10, 8, 3, -1.0, 2), straight(8, 100, 0, 2.0, 92)};
  path.end_pose = {20.2, 0.0, 0.0};  // nearest point: x = 20
  const auto poses = manoeuvre_poses(path);
  ASSERT_EQ(poses.size(), 3u + 13u);
  EXPECT_DOUBLE_EQ(poses.back().x, 20.0);
}

TEST(ManoeuvreView, FramesTheFootprintsAndTheObjectsNextToThem) {
  PullOutRequest request;
  request.ego_pose = {10.0, 3.0, 0.0};
  Object close;  // 1 m behind the rear bumper, partly inside a 1 m margin
  close.pose = {6.0, 3.0, 0.0};
  close.length_m = 4.0;
  close.width_m = 2.0;
  Object far = close;
  far.pose = {60.0, 3.0, 0.0};
  Object huge = close;           // a 200 m wall along the road: cut at the view's edge, not framed whole
  huge.pose = {10.0, 5.4, 0.0};  // y 4.9..5.9: meets the start's box (up to y 4.948)
  huge.length_m = 200.0;
  huge.width_m = 1.0;
  request.objects = {close, far, huge};
  const VehicleInfo vehicle;  // 1.1 m behind base_link, 3.79 m ahead, 0.948 m each side
  const Box start = manoeuvre_view(request, vehicle, nullptr, 1.0);
  EXPECT_NEAR(start.min_x, 4.0, 1e-9);  // the close car's rear
  EXPECT_NEAR(start.max_x, 10.0 + 3.79 + 1.0, 1e-9);
  EXPECT_NEAR(start.max_y, 3.0 + 0.948 + 1.0, 1e-9);  // the wall is not taken in whole
  EXPECT_NEAR(start.min_y, 3.0 - 0.948 - 1.0, 1e-9);  // below the close car's right side (y 2)
  // With a path: its footprints up to the end pose, not the lane beyond.
  PullOutPath path;
  path.found = true;
  path.partial_paths = {straight(10, 30, 3, 2.0, 20), straight(30, 150, 0, 2.0, 120)};
  path.end_pose = {40.0, 0.0, 0.0};
  const Box with_path = manoeuvre_view(request, vehicle, &path, 1.0);
  EXPECT_NEAR(with_path.max_x, 40.0 + 3.79 + 1.0, 1e-9);
  EXPECT_NEAR(with_path.min_y, -0.948 - 1.0, 1e-9);
}

TEST(SegmentIsReverse, ByTheMajorityOfItsVelocities) {
  EXPECT_TRUE(segment_is_reverse(straight(10, 8, 3, -1.0, 2)));
  EXPECT_FALSE(segment_is_reverse(straight(8, 10, 3, 1.0, 2)));
}

}  // namespace
}  // namespace pullout::cli
