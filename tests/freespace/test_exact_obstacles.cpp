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

}  // namespace
}  // namespace pullout
