// The freespace collision test against the true polygons and lane edges (issues 12 and 13): a
// costmap built from polygons decides partly covered cells by the exact shapes. Oracle: the
// Euclidean distance between the vehicle rectangle and each obstacle polygon / the lane boundary,
// written here from point-segment distances and a winding-number containment test (none of the
// code under test). The checker must say "collision" iff the oracle's distance is 0 (or the
// rectangle leaves the lane), for every pose whose distance is not within kTolerance of 0.
//
// Tolerance: the checker works in grid cell units with doubles; coordinates here are below 200
// cells, so each transform and projection is exact to ~1e-13 cells (a few ulps of 200), i.e.
// ~1e-14 m at 0.2 m cells. kTolerance = 1e-6 m is far above that rounding and far below anything
// physical; poses with an oracle distance within it (touching) are not compared.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "../sampling.hpp"
#include "pullout/freespace/costmap.hpp"
#include "pullout/freespace/grid_collision_checker.hpp"
#include "pullout/geometry/angle.hpp"

namespace pullout {
namespace {

constexpr double kTolerance = 1e-6;  // [m] see the file comment

double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

double point_segment(const Vec2& p, const Vec2& a, const Vec2& b) {
  const Vec2 ab = b - a;
  const double l2 = ab.squaredNorm();
  const double t = l2 > 0.0 ? std::clamp((p - a).dot(ab) / l2, 0.0, 1.0) : 0.0;
  return (p - (a + t * ab)).norm();
}

bool segments_cross(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  const double d1 = cross(b - a, c - a);
  const double d2 = cross(b - a, d - a);
  const double d3 = cross(d - c, a - c);
  const double d4 = cross(d - c, b - c);
  return ((d1 > 0) != (d2 > 0)) && ((d3 > 0) != (d4 > 0)) && d1 != 0 && d2 != 0 && d3 != 0 && d4 != 0;
}

double segment_segment(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  if (segments_cross(a, b, c, d)) return 0.0;
  return std::min({point_segment(a, c, d), point_segment(b, c, d), point_segment(c, a, b), point_segment(d, a, b)});
}

// Winding number of a closed polygon around p (non-zero: inside).
bool winding_inside(const std::vector<Vec2>& poly, const Vec2& p) {
  int wn = 0;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Vec2& a = poly[i];
    const Vec2& b = poly[(i + 1) % poly.size()];
    if (a.y() <= p.y()) {
      if (b.y() > p.y() && cross(b - a, p - a) > 0) ++wn;
    } else if (b.y() <= p.y() && cross(b - a, p - a) < 0) {
      --wn;
    }
  }
  return wn != 0;
}

// The four corners of the rectangle x in [-rear, front], y in [-right, left] at pose.
std::vector<Vec2> rectangle(const Pose2& pose, double front, double rear, double left, double right) {
  const double c = std::cos(pose.yaw);
  const double s = std::sin(pose.yaw);
  std::vector<Vec2> out;
  for (const auto& [x, y] : {std::pair{front, left}, {-rear, left}, {-rear, -right}, {front, -right}}) {
    out.emplace_back(pose.x + c * x - s * y, pose.y + s * x + c * y);
  }
  return out;
}

// Distance between two closed polygons (0 when they overlap or one contains the other).
double polygon_distance(const std::vector<Vec2>& p, const std::vector<Vec2>& q) {
  if (winding_inside(q, p[0]) || winding_inside(p, q[0])) return 0.0;
  double d = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (std::size_t k = 0; k < q.size(); ++k) {
      d = std::min(d, segment_segment(p[i], p[(i + 1) % p.size()], q[k], q[(k + 1) % q.size()]));
    }
  }
  return d;
}

// Distance of the rectangle to the lane's boundary, negative when it is not inside the lane.
double lane_margin(const std::vector<Vec2>& rect, const std::vector<Vec2>& lane) {
  double d = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < rect.size(); ++i) {
    for (std::size_t k = 0; k < lane.size(); ++k) {
      d = std::min(d, segment_segment(rect[i], rect[(i + 1) % rect.size()], lane[k], lane[(k + 1) % lane.size()]));
    }
  }
  if (d > 0.0 && !winding_inside(lane, rect[0])) return -d;
  return d;
}

TEST(ExactObstacles, CheckerAgreesWithPolygonOracleNearPolygonsAndLaneEdges) {
  // A lane at 17 degrees (its edges cross cells at all angles), three non-convex or convex
  // obstacles in it, 0.2 m cells.
  const Pose2 lane_pose{3.0, 2.0, 0.3};
  const auto at = [&](double x, double y) {
    const double c = std::cos(lane_pose.yaw);
    const double s = std::sin(lane_pose.yaw);
    return Vec2{lane_pose.x + c * x - s * y, lane_pose.y + s * x + c * y};
  };
  const std::vector<Vec2> lane{at(0, 0), at(30, 0), at(30, 9), at(0, 9)};
  const std::vector<std::vector<Vec2>> obstacles{
      {at(6, 0.3), at(10.5, 0.3), at(10.5, 2.2), at(6, 2.2)},                        // a parked car
      {at(15, 4), at(19, 4), at(19, 8), at(18.1, 8), at(18.1, 4.93), at(15, 4.93)},  // an L (non-convex)
      {at(22, 1), at(26, 1.5), at(23.3, 2.6), at(26.2, 5.1), at(21.7, 4.4)},         // an arrow (non-convex)
  };
  std::vector<std::pair<Vec2, Vec2>> outline;
  for (std::size_t k = 0; k < lane.size(); ++k) outline.emplace_back(lane[k], lane[(k + 1) % lane.size()]);
  Aabb extent;
  for (const Vec2& p : lane) extent.extend(p);
  extent.extend(extent.min - Vec2(1.0, 1.0));
  extent.extend(extent.max + Vec2(1.0, 1.0));
  std::vector<Polygon> polys;
  for (const auto& o : obstacles) polys.push_back(Polygon(o.begin(), o.end()));
  const double res = 0.2;
  const Costmap map = Costmap::from_polygons(extent, res, {Polygon(lane.begin(), lane.end())}, outline, polys);
  const double front = 3.76, rear = 0.929, half = 0.971;  // TPCAP's car
  const GridCollisionChecker checker(map, Footprint{front, rear, half, half});

  std::mt19937 rng(20261202);
  std::uniform_real_distribution<double> off(-2.5, 2.5), yaw(-kPi, kPi), unit(0.0, 1.0);
  // Poses near the shapes: around a random point of an obstacle's or the lane's boundary.
  std::vector<std::vector<Vec2>> boundaries = obstacles;
  boundaries.push_back(lane);
  std::uniform_int_distribution<std::size_t> pick(0, boundaries.size() - 1);
  int compared = 0, collisions = 0, free_near = 0, skipped = 0;
  for (int n = 0; n < 20000; ++n) {
    const auto& b = boundaries[pick(rng)];
    const std::size_t k = std::uniform_int_distribution<std::size_t>(0, b.size() - 1)(rng);
    const Vec2 p = b[k] + unit(rng) * (b[(k + 1) % b.size()] - b[k]);
    const Pose2 pose{p.x() + off(rng), p.y() + off(rng), yaw(rng)};
    const auto rect = rectangle(pose, front, rear, half, half);
    double d = lane_margin(rect, lane);
    for (const auto& o : obstacles) d = std::min(d, polygon_distance(rect, o));
    // Exactly 0: the rectangle crosses or contains a shape (an overlap); within the tolerance but
    // not 0: touching up to rounding, not compared.
    if (d != 0.0 && std::abs(d) <= kTolerance) {
      ++skipped;
      continue;
    }
    const bool expected = d <= 0.0;
    ++compared;
    collisions += expected ? 1 : 0;
    free_near += (d > kTolerance && d < res) ? 1 : 0;
    ASSERT_EQ(checker.collides(pose), expected)
        << "pose " << pose.x << " " << pose.y << " " << pose.yaw << " oracle distance " << d;
  }
  // The comparison covered both answers, and poses closer than a cell to a shape (where a
  // rasterised check says collision) in numbers.
  EXPECT_GT(compared, 19000);
  EXPECT_GT(collisions, 3000);
  EXPECT_GT(free_near, 300) << "free poses within a cell of a shape";
}

// A random star-shaped polygon around centre (convex or not): n vertices at increasing angles,
// radii between r_min and r_max.
std::vector<Vec2> random_star(std::mt19937& rng, const Vec2& centre, double r_min, double r_max) {
  const int n = std::uniform_int_distribution<int>(3, 9)(rng);
  std::uniform_real_distribution<double> radius(r_min, r_max), jitter(0.1, 0.9);
  const double start = std::uniform_real_distribution<double>(-kPi, kPi)(rng);
  std::vector<Vec2> out;
  for (int i = 0; i < n; ++i) {
    const double a = start + 2.0 * kPi * (i + jitter(rng)) / n;
    const double r = radius(rng);
    out.emplace_back(centre.x() + r * std::cos(a), centre.y() + r * std::sin(a));
  }
  return out;
}

// The fast paths of the exact test (rows of a footprint piece, the partial cells' shapes collected
// a row at a time) against the oracle on random maps: random footprints (short ones checked in one
// piece, long and wide ones in several), random cell sizes, many random obstacles of all sizes,
// poses near the obstacles' boundaries. A wrong early out or a cell left out of a row shows as
// "free" where the oracle has an overlap.
TEST(ExactObstacles, RandomFootprintsAgreeWithPolygonOracleOnRandomMaps) {
  std::mt19937 rng(1302);
  std::uniform_real_distribution<double> unit(0.0, 1.0), yaw(-kPi, kPi);
  int compared = 0, collisions = 0, free_near = 0;
  for (int map_index = 0; map_index < 12; ++map_index) {
    const double res = std::uniform_real_distribution<double>(0.05, 0.3)(rng);
    const double size = 30.0;
    const std::vector<Vec2> lane{{0.0, 0.0}, {size, 0.0}, {size, size}, {0.0, size}};
    std::vector<std::pair<Vec2, Vec2>> outline;
    for (std::size_t k = 0; k < lane.size(); ++k) outline.emplace_back(lane[k], lane[(k + 1) % lane.size()]);
    std::vector<std::vector<Vec2>> obstacles;
    const int count = std::uniform_int_distribution<int>(5, 25)(rng);
    for (int i = 0; i < count; ++i) {
      const Vec2 centre(3.0 + 24.0 * unit(rng), 3.0 + 24.0 * unit(rng));
      const double r_max = std::uniform_real_distribution<double>(0.05, 2.5)(rng);
      obstacles.push_back(random_star(rng, centre, 0.3 * r_max, r_max));
    }
    std::vector<Polygon> polys;
    for (const auto& o : obstacles) polys.push_back(Polygon(o.begin(), o.end()));
    Aabb extent;
    for (const Vec2& p : lane) extent.extend(p);
    extent.extend(extent.min - Vec2(1.0, 1.0));
    extent.extend(extent.max + Vec2(1.0, 1.0));
    const Costmap map = Costmap::from_polygons(extent, res, {Polygon(lane.begin(), lane.end())}, outline, polys);
    ASSERT_TRUE(map.has_partial());
    for (int f = 0; f < 4; ++f) {
      const double front = std::uniform_real_distribution<double>(0.2, 6.0)(rng);
      const double rear = std::uniform_real_distribution<double>(0.0, 2.0)(rng);
      const double left = std::uniform_real_distribution<double>(0.1, 1.8)(rng);
      const double right = std::uniform_real_distribution<double>(0.1, 1.8)(rng);
      const GridCollisionChecker checker(map, Footprint{front, rear, left, right});
      std::uniform_real_distribution<double> off(-(front + left), front + left);
      for (int n = 0; n < test::sampled_count(1500); ++n) {
        const auto& b = obstacles[std::uniform_int_distribution<std::size_t>(0, obstacles.size() - 1)(rng)];
        const std::size_t k = std::uniform_int_distribution<std::size_t>(0, b.size() - 1)(rng);
        const Vec2 p = b[k] + unit(rng) * (b[(k + 1) % b.size()] - b[k]);
        const Pose2 pose{p.x() + off(rng), p.y() + off(rng), yaw(rng)};
        const auto rect = rectangle(pose, front, rear, left, right);
        double d = lane_margin(rect, lane);
        for (const auto& o : obstacles) d = std::min(d, polygon_distance(rect, o));
        if (d != 0.0 && std::abs(d) <= kTolerance) continue;  // touching up to rounding
        const bool expected = d <= 0.0;
        ++compared;
        collisions += expected ? 1 : 0;
        free_near += (d > kTolerance && d < res) ? 1 : 0;
        ASSERT_EQ(checker.collides(pose), expected)
            << "map " << map_index << " res " << res << " footprint " << front << " " << rear << " " << left << " "
            << right << " pose " << pose.x << " " << pose.y << " " << pose.yaw << " oracle distance " << d;
      }
    }
  }
  EXPECT_GT(compared, test::sampled_count(70000));
  EXPECT_GT(collisions, test::sampled_count(10000));
  EXPECT_GT(free_near, test::sampled_count(1000)) << "free poses within a cell of a shape";
}

// partial_shapes_in_row gives the set of shapes of the occupied cells of the row range, which the
// cell-by-cell partial_shapes gives too, with no id repeated back to back.
TEST(ExactObstacles, RowOfPartialShapesIsTheSetOfItsCellsShapes) {
  std::mt19937 rng(2012);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Polygon> polys;
  for (int i = 0; i < 40; ++i) {
    const auto star = random_star(rng, Vec2(1.0 + 18.0 * unit(rng), 1.0 + 18.0 * unit(rng)), 0.05, 1.5);
    polys.push_back(Polygon(star.begin(), star.end()));
  }
  const std::vector<Vec2> lane{{0.0, 0.0}, {20.0, 0.0}, {20.0, 20.0}, {0.0, 20.0}};
  std::vector<std::pair<Vec2, Vec2>> outline;
  for (std::size_t k = 0; k < lane.size(); ++k) outline.emplace_back(lane[k], lane[(k + 1) % lane.size()]);
  Aabb extent;
  extent.extend(Vec2(-1.0, -1.0));
  extent.extend(Vec2(21.0, 21.0));
  const Costmap map = Costmap::from_polygons(extent, 0.1, {Polygon(lane.begin(), lane.end())}, outline, polys);
  ASSERT_TRUE(map.has_partial());
  int nonempty = 0;
  for (int n = 0; n < 3000; ++n) {
    const int j = std::uniform_int_distribution<int>(0, map.height() - 1)(rng);
    int c0 = std::uniform_int_distribution<int>(0, map.width() - 1)(rng);
    int c1 = std::uniform_int_distribution<int>(0, map.width() - 1)(rng);
    if (c0 > c1) std::swap(c0, c1);
    std::vector<std::uint32_t> row;
    map.partial_shapes_in_row(c0, c1, j, row);
    std::vector<std::uint32_t> cells;
    for (int i = c0; i <= c1; ++i) {
      if (map.occupied(i, j)) map.partial_shapes(i, j, cells);
    }
    for (std::size_t k = 1; k < row.size(); ++k) ASSERT_NE(row[k], row[k - 1]);
    std::sort(row.begin(), row.end());
    row.erase(std::unique(row.begin(), row.end()), row.end());
    std::sort(cells.begin(), cells.end());
    cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
    ASSERT_EQ(row, cells) << "row " << j << " columns " << c0 << ".." << c1;
    nonempty += row.empty() ? 0 : 1;
  }
  EXPECT_GT(nonempty, 1000);
}

}  // namespace
}  // namespace pullout
