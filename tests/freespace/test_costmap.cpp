// The freespace costmap and the exact footprint test. Oracles: brute force over every cell (the
// distance transform), and a separating-axis test of the rectangle against each occupied square
// (the collision test), independent of the row-strip walk under test.
#include "pullout/freespace/costmap.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include "../sampling.hpp"
#include "pullout/freespace/grid_collision_checker.hpp"
#include "pullout/geometry/angle.hpp"

namespace pullout {
namespace {

Costmap empty_map(int w, int h, double res, const Pose2& origin = {}) {
  return Costmap(origin, res, w, h, std::vector<std::uint8_t>(static_cast<std::size_t>(w * h), 0));
}

// Occupied cells of the grid.
std::size_t occupied_count(const Costmap& map) {
  std::size_t n = 0;
  for (int j = 0; j < map.height(); ++j) {
    for (int i = 0; i < map.width(); ++i) n += map.occupied(i, j) ? 1 : 0;
  }
  return n;
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

TEST(Costmap, InsideDrivableIsTheEvenOddRuleOverThePolygons) {
  // Two lanes of a 30 m bend (hundreds of edges each, the inner one clockwise) and a square that
  // sticks out of the grid; 0.1 m cells. inside_drivable looks only at the edges near a point's
  // row: its answer must be point_in_polygon's over the polygons (grid frame), also for points on
  // vertex heights and row boundaries, outside the grid's rows, and on a vertex.
  const auto lane = [](double r_in, double r_out, bool clockwise) {
    Polygon p;
    for (int k = 0; k <= 200; ++k) p.emplace_back(r_in * std::cos(0.01 * k), r_in * std::sin(0.01 * k) - 25.0);
    for (int k = 200; k >= 0; --k) p.emplace_back(r_out * std::cos(0.01 * k), r_out * std::sin(0.01 * k) - 25.0);
    if (clockwise) std::reverse(p.begin(), p.end());
    return p;
  };
  const std::vector<Polygon> lanes{
      lane(27.0, 30.0, false), lane(30.0, 33.0, true), {{20.0, -2.0}, {26.0, -2.0}, {26.0, 40.0}, {20.0, 40.0}}};
  Aabb extent;
  extent.extend({15.0, -26.0});
  extent.extend({34.0, 30.0});
  const Costmap m = Costmap::from_polygons(extent, 0.1, lanes, {}, {});
  std::vector<Polygon> grid_lanes;
  for (const Polygon& p : lanes) {
    Polygon g;
    for (const Vec2& v : p) g.push_back(m.to_grid(v));
    grid_lanes.push_back(g);
  }
  const auto expected = [&](const Vec2& q) {
    return std::any_of(grid_lanes.begin(), grid_lanes.end(), [&](const Polygon& g) { return point_in_polygon(g, q); });
  };
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> x(-5.0, m.width() + 5.0);
  std::uniform_real_distribution<double> y(-5.0, m.height() + 5.0);
  std::vector<Vec2> points;
  for (int k = 0; k < 20000; ++k) points.emplace_back(x(rng), y(rng));
  for (const Polygon& g : grid_lanes) {
    for (const Vec2& v : g) {
      points.push_back(v);
      points.emplace_back(x(rng), v.y());
      points.emplace_back(v.x() + 0.01, std::floor(v.y()));
      points.emplace_back(v.x() - 0.01, std::floor(v.y()) + 1.0);
    }
  }
  int inside = 0;
  for (const Vec2& q : points) {
    ASSERT_EQ(m.inside_drivable(q), expected(q)) << q.x() << ", " << q.y();
    inside += expected(q) ? 1 : 0;
  }
  EXPECT_GT(inside, 1000);  // the points test both answers
  EXPECT_LT(inside, static_cast<int>(points.size()) - 1000);
}

TEST(Costmap, PolygonsOfAnySizeRasterise) {
  // Coordinates far beyond the range of int cell indices: clamped to the grid, not converted.
  Costmap map = empty_map(10, 10, 1.0);
  map.add_obstacles({{{1e300, 1e300}, {1.1e300, 1e300}, {1.1e300, 1.1e300}}});
  EXPECT_EQ(occupied_count(map), 0u);  // far outside: nothing
  // A wall x in [2.5, 3.5] from y = -1e300 to 1e300: columns 2 and 3 of every row.
  map.add_obstacles({{{2.5, -1e300}, {3.5, -1e300}, {3.5, 1e300}, {2.5, 1e300}}});
  EXPECT_EQ(occupied_count(map), 20u);
  for (int j = 0; j < 10; ++j) {
    EXPECT_TRUE(map.occupied(2, j) && map.occupied(3, j)) << j;
    EXPECT_FALSE(map.occupied(1, j) || map.occupied(4, j)) << j;
  }
  map.add_obstacles({{{-1e300, -1e300}, {1e300, -1e300}, {1e300, 1e300}, {-1e300, 1e300}}});
  EXPECT_EQ(occupied_count(map), 100u);

  // A drivable area far larger than the extent: every cell free (no outline given) except rows 4
  // and 5, which an obstacle band y in [4.5, 5.5] as wide as the drivable area blocks.
  Aabb extent;
  extent.extend({0, 0});
  extent.extend({10, 10});
  const Costmap lot =
      Costmap::from_polygons(extent, 1.0, {{{-1e300, -1e300}, {1e300, -1e300}, {1e300, 1e300}, {-1e300, 1e300}}}, {},
                             {{{-1e300, 4.5}, {1e300, 4.5}, {1e300, 5.5}, {-1e300, 5.5}}});
  EXPECT_EQ(lot.width(), 10);
  EXPECT_EQ(lot.height(), 10);
  EXPECT_EQ(occupied_count(lot), 20u);
  EXPECT_TRUE(lot.occupied(0, 4) && lot.occupied(9, 5));
  EXPECT_FALSE(lot.occupied(0, 3) || lot.occupied(9, 6));
  // An extent wider than 16384 cells is cut there; an inverted one gives one cell.
  Aabb wide;
  wide.extend({0, 0});
  wide.extend({1e300, 2});
  EXPECT_EQ(Costmap::from_polygons(wide, 1.0, {}, {}, {}).width(), 16384);
  Aabb inverted;
  inverted.min = {1e300, 0.0};
  inverted.max = {0.0, 2.0};
  EXPECT_EQ(Costmap::from_polygons(inverted, 1.0, {}, {}, {}).width(), 1);
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
    const double yaw = kPi / 4.0 - std::atan2(fp.left, fp.front);
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
  std::uniform_real_distribution<double> x(0.0, w * res), y(0.0, h * res), yaw(-kPi, kPi);
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

// --- Randomised property tests against slow, obviously correct references -----------------------

// A costmap of w x h cells with clusters of occupied cells (random blocks and single cells).
Costmap random_map(std::mt19937& rng, int w, int h, double res, const Pose2& origin,
                   std::vector<std::pair<int, int>>& cells, int clusters = 25) {
  std::vector<std::uint8_t> occ(static_cast<std::size_t>(w * h), 0);
  std::uniform_int_distribution<int> xi(0, w - 1), yi(0, h - 1), size(1, 6);
  for (int k = 0; k < clusters; ++k) {
    const int i0 = xi(rng), j0 = yi(rng);
    const int sw = k % 3 == 0 ? 1 : size(rng), sh = k % 3 == 0 ? 1 : size(rng);
    for (int j = j0; j < std::min(h, j0 + sh); ++j) {
      for (int i = i0; i < std::min(w, i0 + sw); ++i) occ[static_cast<std::size_t>(j * w + i)] = 1;
    }
  }
  cells.clear();
  for (int j = 0; j < h; ++j) {
    for (int i = 0; i < w; ++i) {
      if (occ[static_cast<std::size_t>(j * w + i)] != 0) cells.emplace_back(i, j);
    }
  }
  return Costmap(origin, res, w, h, std::move(occ));
}

// Distance between the closed convex polygons a and b (0 when they meet; the caller knows): the
// nearest points of two disjoint convex polygons include a vertex of one of them.
double polygon_distance(const std::array<Vec2, 4>& a, const std::array<Vec2, 4>& b) {
  const auto point_segment = [](const Vec2& p, const Vec2& s0, const Vec2& s1) {
    const Vec2 d = s1 - s0;
    const double t = std::clamp((p - s0).dot(d) / d.squaredNorm(), 0.0, 1.0);
    return (p - (s0 + t * d)).norm();
  };
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < 4; ++i) {
    for (std::size_t k = 0; k < 4; ++k) {
      best = std::min(best, point_segment(a[i], b[k], b[(k + 1) % 4]));
      best = std::min(best, point_segment(b[i], a[k], a[(k + 1) % 4]));
    }
  }
  return best;
}

// The reference, in the grid frame (cell units): the footprint's map-frame corners mapped with
// Costmap::to_grid, the outside-the-grid rule, then a separating-axis test against every occupied
// cell square. Also the true distance [m] to the nearest occupied square or the grid's outside.
struct Reference {
  bool collides{false};
  double distance{0.0};
};
Reference reference(const Costmap& m, const std::vector<std::pair<int, int>>& cells, const Footprint& fp,
                    const Pose2& pose) {
  std::array<Vec2, 4> g;
  const auto c = footprint_corners(fp, pose);
  for (std::size_t i = 0; i < 4; ++i) g[i] = m.to_grid(c[i]);
  Reference r;
  r.distance = std::numeric_limits<double>::infinity();
  for (const Vec2& p : g) {
    r.collides = r.collides || p.x() < 0 || p.y() < 0 || p.x() >= m.width() || p.y() >= m.height();
    r.distance = std::min({r.distance, p.x(), p.y(), m.width() - p.x(), m.height() - p.y()});
  }
  for (const auto& [i, j] : cells) {
    const double x0 = i, y0 = j, x1 = i + 1.0, y1 = j + 1.0;
    if (rectangle_meets_square(g, x0, y0, x1, y1)) {
      r.collides = true;
      r.distance = 0.0;
      break;
    }
    r.distance = std::min(r.distance, polygon_distance(g, {Vec2{x0, y0}, Vec2{x1, y0}, Vec2{x1, y1}, Vec2{x0, y1}}));
  }
  r.distance = r.collides ? 0.0 : r.distance * m.resolution();
  return r;
}

TEST(Costmap, OccupiedInBoxMatchesBruteForce) {
  std::mt19937 rng(3);
  std::vector<std::pair<int, int>> cells;
  const Costmap m = random_map(rng, 31, 17, 0.1, {}, cells);
  std::uniform_int_distribution<int> xi(-3, 33), yi(-3, 19);
  for (int n = 0; n < 2000; ++n) {
    const int c0 = xi(rng), c1 = xi(rng), r0 = yi(rng), r1 = yi(rng);
    long long expected = 0;
    for (int j = r0; j <= r1; ++j) {
      for (int i = c0; i <= c1; ++i) expected += m.occupied(i, j) ? 1 : 0;
    }
    ASSERT_EQ(m.occupied_in_box(c0, r0, c1, r1), expected) << c0 << " " << r0 << " " << c1 << " " << r1;
    if (c0 <= c1) {
      long long in_row = 0;
      for (int i = c0; i <= c1; ++i) in_row += m.occupied(i, r0) ? 1 : 0;
      ASSERT_EQ(m.occupied_in_row(r0, c0, c1), in_row) << r0 << " " << c0 << " " << c1;
    }
  }
}

// Random poses near obstacles (the rear axle within a footprint length of an occupied cell), on
// maps with and without a turned origin, at two resolutions and for a long and a square footprint:
// collides() agrees with the reference, and the clearance bound never exceeds the true distance.
TEST(GridCollisionChecker, AgreesWithReferenceNearObstaclesAndBoundIsALowerBound) {
  struct Case {
    double res;
    Pose2 origin;
    Footprint fp;
  };
  const std::vector<Case> cases{{0.1, {}, {3.9, 1.1, 0.95, 0.95}},
                                {0.2, {}, {3.9, 1.1, 0.95, 0.95}},
                                {0.15, {3.0, -2.0, 0.7}, {2.0, 0.6, 0.5, 0.7}},
                                {0.1, {-1.5, 4.0, -2.3}, {3.9, 1.1, 0.95, 0.95}},
                                {0.25, {0.5, 0.25, 0.0}, {0.6, 0.6, 0.6, 0.6}}};
  std::mt19937 rng(2024);
  int hits = 0;
  int total = 0;
  int positive_bounds = 0;
  for (const Case& cs : cases) {
    std::vector<std::pair<int, int>> cells;
    const Costmap m = random_map(rng, 200, 160, cs.res, cs.origin, cells, 60);
    const GridCollisionChecker checker(m, cs.fp);
    std::uniform_int_distribution<std::size_t> pick(0, cells.size() - 1);
    std::uniform_real_distribution<double> off(-1.0, 1.0), yaw(-kPi, kPi);
    const double reach = 1.5 * cs.fp.length() + 1.0;
    for (int n = 0; n < test::sampled_count(3000); ++n) {
      const auto [ci, cj] = cells[pick(rng)];
      const Vec2 centre = m.to_map({ci + 0.5, cj + 0.5});
      const Pose2 pose{centre.x() + reach * off(rng), centre.y() + reach * off(rng), yaw(rng)};
      const Reference ref = reference(m, cells, cs.fp, pose);
      double bound = -1.0;
      ASSERT_EQ(checker.collides(pose, bound), ref.collides)
          << pose.x << " " << pose.y << " " << pose.yaw << " res " << cs.res;
      ASSERT_EQ(checker.collides(pose), ref.collides);
      const double lower = checker.clearance_lower_bound(pose);
      ASSERT_GE(lower, 0.0);
      ASSERT_LE(lower, ref.distance) << pose.x << " " << pose.y << " " << pose.yaw << " res " << cs.res;
      ASSERT_LE(bound, ref.distance);
      hits += ref.collides ? 1 : 0;
      positive_bounds += lower > 0.0 ? 1 : 0;
      ++total;
    }
  }
  std::printf("%d of %d poses collide, %d positive bounds\n", hits, total, positive_bounds);
  // Both outcomes well represented, and the bound is not trivially 0.
  EXPECT_GT(hits, total / 5);
  EXPECT_LT(hits, total * 4 / 5);
  EXPECT_GT(positive_bounds, total / 20);
}

// A footprint of hundreds of cells a side: its pieces span more rows than the checker keeps on
// the stack (at 5 mm cells, 2.6 m x 1.8 m in 8 x 8 pieces of 65 x 45 cells, ~78 rows at 45 deg).
TEST(GridCollisionChecker, AgreesWithReferenceForAHugeFootprintOnAFineGrid) {
  std::mt19937 rng(99);
  std::vector<std::pair<int, int>> cells;
  const Costmap m = random_map(rng, 1000, 1000, 0.005, {0.3, -0.2, 0.4}, cells, 5);
  const Footprint fp{2.0, 0.6, 0.9, 0.9};
  const GridCollisionChecker checker(m, fp);
  std::uniform_real_distribution<double> u(-1.0, 1.0), yaw(-kPi, kPi);
  int hits = 0;
  for (int n = 0; n < 300; ++n) {
    const Vec2 p = m.to_map({500.0 + 40.0 * u(rng), 500.0 + 40.0 * u(rng)});
    const Pose2 pose{p.x(), p.y(), yaw(rng)};
    const Reference ref = reference(m, cells, fp, pose);
    ASSERT_EQ(checker.collides(pose), ref.collides) << pose.x << " " << pose.y << " " << pose.yaw;
    ASSERT_LE(checker.clearance_lower_bound(pose), ref.distance);
    hits += ref.collides ? 1 : 0;
  }
  std::printf("%d of 300 poses collide\n", hits);
  EXPECT_GT(hits, 30);
  EXPECT_LT(hits, 270);
}

// Axis-aligned poses (yaw 0, pi/2, pi, -pi/2 with exact cos/sin) on a lattice of 1/16 m around a
// few cells of 0.25 m: every value is exact in binary, so the rectangle's edges lie exactly on
// cell boundaries (and corners on cell corners) at many poses. Touching is a collision, touching
// the grid's far edges leaves the grid, touching its near edges does not.
TEST(GridCollisionChecker, ExactWhenEdgesLieOnCellBoundaries) {
  const double res = 0.25;
  const int w = 24;
  const int h = 20;
  const Pose2 origin{-2.0, 1.5, 0.0};
  const std::vector<std::pair<int, int>> cells{{9, 7}, {10, 7}, {14, 12}, {4, 15}};
  std::vector<std::uint8_t> occ(static_cast<std::size_t>(w * h), 0);
  for (const auto& [i, j] : cells) occ[static_cast<std::size_t>(j * w + i)] = 1;
  const Costmap m(origin, res, w, h, std::move(occ));
  const Footprint fp{1.5, 0.5, 0.75, 0.25};  // asymmetric: every side lands somewhere else
  const GridCollisionChecker checker(m, fp);
  struct Heading {
    double yaw, c, s;
  };
  const Heading headings[] = {{0.0, 1.0, 0.0}, {kPi / 2, 0.0, 1.0}, {kPi, -1.0, 0.0}, {-kPi / 2, 0.0, -1.0}};
  int touching = 0;
  int collisions = 0;
  for (const Heading& hd : headings) {
    for (int a = -8; a <= 16 * w * res + 8; ++a) {
      for (int b = -8; b <= 16 * h * res + 8; ++b) {
        const Pose2 pose{origin.x + a / 16.0, origin.y + b / 16.0, hd.yaw};
        // The rectangle's x and y extents in the grid frame [cells], exactly.
        const double gx = a / 16.0 / res;
        const double gy = b / 16.0 / res;
        const double lx0 = -fp.rear / res, lx1 = fp.front / res, ly0 = -fp.right / res, ly1 = fp.left / res;
        double x0 = 0, x1 = 0, y0 = 0, y1 = 0;
        if (hd.c > 0.5) {
          x0 = gx + lx0, x1 = gx + lx1, y0 = gy + ly0, y1 = gy + ly1;
        } else if (hd.s > 0.5) {
          x0 = gx - ly1, x1 = gx - ly0, y0 = gy + lx0, y1 = gy + lx1;
        } else if (hd.c < -0.5) {
          x0 = gx - lx1, x1 = gx - lx0, y0 = gy - ly1, y1 = gy - ly0;
        } else {
          x0 = gx + ly0, x1 = gx + ly1, y0 = gy - lx1, y1 = gy - lx0;
        }
        bool expected = x0 < 0 || y0 < 0 || x1 >= w || y1 >= h;
        for (const auto& [i, j] : cells) {
          const bool meets = x0 <= i + 1 && i <= x1 && y0 <= j + 1 && j <= y1;  // closed boxes
          expected = expected || meets;
          touching += meets && (x0 == i + 1 || x1 == i || y0 == j + 1 || y1 == j) ? 1 : 0;
        }
        double bound = -1.0;
        ASSERT_EQ(checker.collides(pose, hd.c, hd.s, bound), expected)
            << "yaw " << hd.yaw << " grid rectangle [" << x0 << ", " << x1 << "] x [" << y0 << ", " << y1 << "]";
        if (hd.yaw == 0.0) {
          ASSERT_EQ(checker.collides(pose), expected);
        }
        if (expected) {
          ASSERT_EQ(bound, 0.0);
        }
        collisions += expected ? 1 : 0;
      }
    }
  }
  EXPECT_GT(touching, 100);  // the lattice does hit the exact touches
  EXPECT_GT(collisions, 1000);
}

}  // namespace
}  // namespace pullout
