// The freespace costmap and the exact footprint test. Oracles: brute force over every cell (the
// distance transform), and a separating-axis test of the rectangle against each occupied square
// (the collision test), independent of the row-strip walk under test.
#include "pullout/freespace/costmap.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "pullout/freespace/grid_collision_checker.hpp"

namespace pullout {
namespace {

Costmap empty_map(int w, int h, double res, const Pose2& origin = {}) {
  return Costmap(origin, res, w, h, std::vector<std::uint8_t>(static_cast<std::size_t>(w * h), 0));
}

Costmap with_cells(int w, int h, double res, const std::vector<std::pair<int, int>>& cells) {
  std::vector<std::uint8_t> occ(static_cast<std::size_t>(w * h), 0);
  for (const auto& [i, j] : cells) occ[static_cast<std::size_t>(j * w + i)] = 1;
  return Costmap({}, res, w, h, std::move(occ));
}

// Separating axes of a rectangle (corners) and an axis-aligned square [x0,x1]x[y0,y1]: they
// share a point iff no axis separates them (touching shares a point).
bool rectangle_meets_square(const std::array<Vec2, 4>& r, double x0, double y0, double x1, double y1) {
  const std::array<Vec2, 4> sq{Vec2{x0, y0}, Vec2{x1, y0}, Vec2{x1, y1}, Vec2{x0, y1}};
  const Vec2 axes[4] = {{1, 0}, {0, 1}, (r[1] - r[0]).normalized(), (r[2] - r[1]).normalized()};
  for (const Vec2& a : axes) {
    double rmin = 1e300, rmax = -1e300, smin = 1e300, smax = -1e300;
    for (const Vec2& p : r) {
      rmin = std::min(rmin, a.dot(p));
      rmax = std::max(rmax, a.dot(p));
    }
    for (const Vec2& p : sq) {
      smin = std::min(smin, a.dot(p));
      smax = std::max(smax, a.dot(p));
    }
    if (rmax < smin || smax < rmin) return false;
  }
  return true;
}

TEST(Costmap, OccupancyGridThresholdAndUnknown) {
  OccupancyGrid g;
  g.resolution_m = 0.5;
  g.width = 5;
  g.height = 1;
  g.data = {0, 29, 30, 100, -1};
  const Costmap m = Costmap::from_occupancy_grid(g, 30);
  EXPECT_FALSE(m.occupied(0, 0));
  EXPECT_FALSE(m.occupied(1, 0));
  EXPECT_TRUE(m.occupied(2, 0));
  EXPECT_TRUE(m.occupied(3, 0));
  EXPECT_TRUE(m.occupied(4, 0));   // unknown is an obstacle
  EXPECT_TRUE(m.occupied(-1, 0));  // outside the grid too
  EXPECT_TRUE(m.occupied(0, 1));
}

TEST(Costmap, RotatedOriginRoundTrip) {
  const Costmap m = empty_map(10, 10, 0.2, {3.0, -2.0, 0.7});
  const Vec2 p{4.1, -1.3};
  const Vec2 back = m.to_map(m.to_grid(p));
  EXPECT_NEAR(back.x(), p.x(), 1e-12);
  EXPECT_NEAR(back.y(), p.y(), 1e-12);
  // Cell (0, 0)'s outer corner is the origin; one cell along the grid x axis is 0.2 m at 0.7 rad.
  const Vec2 c = m.to_map({1.0, 0.0});
  EXPECT_NEAR(c.x(), 3.0 + 0.2 * std::cos(0.7), 1e-12);
  EXPECT_NEAR(c.y(), -2.0 + 0.2 * std::sin(0.7), 1e-12);
}

TEST(Costmap, DistanceTransformMatchesBruteForce) {
  std::mt19937 rng(7);
  const int w = 37;
  const int h = 23;
  std::vector<std::pair<int, int>> cells;
  std::uniform_int_distribution<int> xi(0, w - 1), yi(0, h - 1);
  for (int k = 0; k < 12; ++k) cells.emplace_back(xi(rng), yi(rng));
  const Costmap m = with_cells(w, h, 0.1, cells);
  for (int j = 0; j < h; ++j) {
    for (int i = 0; i < w; ++i) {
      // The border one cell outside the grid counts as occupied.
      double best = std::min({i + 1.0, j + 1.0, static_cast<double>(w - i), static_cast<double>(h - j)});
      for (const auto& [ci, cj] : cells) best = std::min(best, std::hypot(i - ci, j - cj));
      EXPECT_NEAR(m.centre_distance(i, j), best * 0.1, 1e-5) << i << "," << j;
    }
  }
}

TEST(Costmap, PolygonsRasteriseConservatively) {
  // A 10 m x 4 m lane, a 1 m box obstacle inside it; 0.25 m cells over a 12 x 6 m extent.
  const Polygon lane{{1, 1}, {11, 1}, {11, 5}, {1, 5}};
  const std::vector<std::pair<Vec2, Vec2>> outline{
      {{1, 1}, {11, 1}}, {{11, 1}, {11, 5}}, {{11, 5}, {1, 5}}, {{1, 5}, {1, 1}}};
  const Polygon box{{5.1, 2.1}, {6.1, 2.1}, {6.1, 3.1}, {5.1, 3.1}};
  Aabb extent;
  extent.extend({0, 0});
  extent.extend({12, 6});
  const Costmap m = Costmap::from_polygons(extent, 0.25, {lane}, outline, {box});
  EXPECT_EQ(m.width(), 48);
  EXPECT_EQ(m.height(), 24);
  int i = 0, j = 0;
  m.cell_of({0.5, 0.5}, i, j);
  EXPECT_TRUE(m.occupied(i, j));  // outside the lane
  m.cell_of({3.1, 3.1}, i, j);
  EXPECT_FALSE(m.occupied(i, j));  // inside
  m.cell_of({1.1, 3.1}, i, j);
  EXPECT_FALSE(m.occupied(i, j));  // the cell [1.0, 1.25] lies inside; the outline only bounds it
  m.cell_of({0.9, 3.1}, i, j);
  EXPECT_TRUE(m.occupied(i, j));  // [0.75, 1.0] lies outside
  m.cell_of({5.05, 2.5}, i, j);
  EXPECT_TRUE(m.occupied(i, j));  // [5.0, 5.25] overlaps the box from x = 5.1
  m.cell_of({4.9, 2.5}, i, j);
  EXPECT_FALSE(m.occupied(i, j));
  m.cell_of({6.2, 3.2}, i, j);
  EXPECT_TRUE(m.occupied(i, j));  // [6.0, 6.25] x [3.0, 3.25] holds the box corner (6.1, 3.1)
}

// The footprint (4.6 m x 1.9 m around base_link) against one occupied cell: a few millimetres
// into the cell is a collision, a few millimetres short of it is not, head-on and corner-first.
TEST(GridCollisionChecker, ExactAtTheMillimetre) {
  const double res = 0.2;
  const Costmap m = with_cells(200, 200, res, {{100, 100}});  // cell [20.0, 20.2] x [20.0, 20.2]
  const Footprint fp{3.5, 1.1, 0.95, 0.95};
  const GridCollisionChecker checker(m, fp);
  for (const double gap : {0.003, -0.003}) {
    // Head-on: the front edge at x = 20 - gap.
    const Pose2 pose{20.0 - gap - fp.front, 20.1, 0.0};
    EXPECT_EQ(checker.collides(pose), gap < 0.0) << "head-on gap " << gap;
    // Corner first: the front-left corner is the footprint's extreme point along the diagonal
    // (1, 1) when the vehicle axis is turned atan(left / front) below it; that corner stands at
    // distance gap from the cell's corner (20, 20) along the diagonal.
    const double yaw = M_PI / 4.0 - std::atan2(fp.left, fp.front);
    const Vec2 target = Vec2{20.0, 20.0} - gap * Vec2{1.0, 1.0}.normalized();
    const Vec2 corner{std::cos(yaw) * fp.front - std::sin(yaw) * fp.left,
                      std::sin(yaw) * fp.front + std::cos(yaw) * fp.left};
    const Vec2 base = target - corner;
    EXPECT_EQ(checker.collides({base.x(), base.y(), yaw}), gap < 0.0) << "corner gap " << gap;
  }
}
TEST(GridCollisionChecker, AgreesWithSeparatingAxesOnRandomPoses) {
  std::mt19937 rng(11);
  const int w = 60;
  const int h = 50;
  const double res = 0.15;
  std::vector<std::pair<int, int>> cells;
  std::uniform_int_distribution<int> xi(0, w - 1), yi(0, h - 1);
  for (int k = 0; k < 40; ++k) cells.emplace_back(xi(rng), yi(rng));
  const Costmap m = with_cells(w, h, res, cells);
  const Footprint fp{2.0, 0.6, 0.5, 0.7};
  const GridCollisionChecker checker(m, fp);
  std::uniform_real_distribution<double> x(0.0, w * res), y(0.0, h * res), yaw(-M_PI, M_PI);
  int hits = 0;
  for (int n = 0; n < 3000; ++n) {
    const Pose2 pose{x(rng), y(rng), yaw(rng)};
    const auto c = footprint_corners(fp, pose);
    bool expected = false;
    for (const auto& p : c) expected = expected || p.x() < 0 || p.y() < 0 || p.x() >= w * res || p.y() >= h * res;
    for (const auto& [i, j] : cells) {
      expected = expected || rectangle_meets_square(c, i * res, j * res, (i + 1) * res, (j + 1) * res);
    }
    hits += expected ? 1 : 0;
    ASSERT_EQ(checker.collides(pose), expected) << pose.x << " " << pose.y << " " << pose.yaw;
    // The clearance bound never exceeds the true distance: positive only when nothing is touched.
    if (checker.clearance_lower_bound(pose) > 0.0) {
      EXPECT_FALSE(expected);
    }
  }
  EXPECT_GT(hits, 100);
  EXPECT_LT(hits, 2900);
}

}  // namespace
}  // namespace pullout
