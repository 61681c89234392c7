#include "pullout/collision/object_checker.hpp"
#include "pullout/geometry/angle.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

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

// The distance between two simple polygons, independently of FCL and of any decomposition: 0
// when an edge of one crosses an edge of the other or a vertex of one lies inside the other
// (even-odd rule), else the least distance from a vertex of one to an edge of the other.
double point_segment(const Vec2& p, const Vec2& a, const Vec2& b) {
  const Vec2 ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (a + t * ab - p).norm();
}
bool inside(const Vec2& p, const Polygon& poly) {
  bool in = false;
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const Vec2& a = poly[i];
    const Vec2& b = poly[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) && p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x()) {
      in = !in;
    }
  }
  return in;
}
bool crossing(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  const auto side = [](const Vec2& o, const Vec2& u, const Vec2& v) {
    return (u.x() - o.x()) * (v.y() - o.y()) - (u.y() - o.y()) * (v.x() - o.x());
  };
  return side(a, b, c) * side(a, b, d) < 0.0 && side(c, d, a) * side(c, d, b) < 0.0;
}
double polygon_distance(const Polygon& p, const Polygon& q) {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (std::size_t j = 0; j < q.size(); ++j) {
      const Vec2& a = p[i];
      const Vec2& b = p[(i + 1) % p.size()];
      const Vec2& c = q[j];
      const Vec2& d = q[(j + 1) % q.size()];
      if (crossing(a, b, c, d)) return 0.0;
      best = std::min({best, point_segment(a, c, d), point_segment(c, a, b)});
    }
  }
  if (inside(p[0], q) || inside(q[0], p)) return 0.0;
  return best;
}

// An L and a U: the vehicle in the notch of the L (or between the arms of the U), where their
// convex hulls would put it inside the obstacle, gets its true distance.
TEST(ObjectChecker, NonConvexObstaclesAreCheckedAgainstTheirTrueShape) {
  const Obstacle l_shape{4, {{8, -1}, {12, -1}, {12, 3}, {11, 3}, {11, 0}, {8, 0}}};
  const ObjectChecker l_checker(kFootprint, {l_shape});
  // The vehicle's box x in [8.5, 9.5], y in [1, 2] lies in the notch: 1 m above the bottom bar,
  // 1.5 m left of the upright.
  const Footprint small{0.5, 0.5, 0.5, 0.5};
  const ObjectChecker notch(small, {l_shape});
  EXPECT_NEAR(notch.clearance({9.0, 1.5, 0.0}).distance, 1.0, kGjkTolerance);
  EXPECT_EQ(notch.clearance({9.0, 1.5, 0.0}).obstacle_id, 4);
  EXPECT_NEAR(l_checker.clearance({0.0, 0.0, 0.0}).distance, 5.0, kGjkTolerance);
  // A U opening upwards, the vehicle standing upright between its arms.
  const Obstacle u_shape{7, {{0, 0}, {6, 0}, {6, 6}, {5, 6}, {5, 1}, {1, 1}, {1, 6}, {0, 6}}};
  const ObjectChecker u_checker(kFootprint, {u_shape});
  // Turned to +y at (3, 1.8): its box x in [2, 4], y in [0.8, 4.8] overlaps the bottom bar.
  EXPECT_DOUBLE_EQ(u_checker.clearance({3.0, 1.8, kPi / 2}).distance, 0.0);
  // At (3, 2.2): rear at y = 1.2, 0.2 m above the bar; sides 1 m from the arms (the hull, the
  // square 0-6, would hold the whole box).
  EXPECT_NEAR(u_checker.clearance({3.0, 2.2, kPi / 2}).distance, 0.2, kGjkTolerance);
}

// Random poses around random simple non-convex polygons (stars: vertices at random radii round a
// centre, so the polygon is simple), against the independent oracle above.
TEST(ObjectChecker, NonConvexDistancesMatchAnIndependentOracle) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Footprint small{1.0, 0.3, 0.4, 0.4};
  int non_convex = 0;
  int near_in_hull = 0;  // poses nearer to the hull than to the polygon: the hull would be wrong there
  for (int trial = 0; trial < 40; ++trial) {
    const int n = 5 + trial % 12;
    Polygon star;
    for (int k = 0; k < n; ++k) {
      const double angle = 2.0 * kPi * (k + 0.3 * unit(rng)) / n;
      const double radius = 1.0 + 3.0 * unit(rng);
      star.push_back({radius * std::cos(angle), radius * std::sin(angle)});
    }
    Polygon hull_check = star;
    bool convex = true;
    for (int k = 0; k < n; ++k) {
      const Vec2& a = star[k];
      const Vec2& b = star[(k + 1) % n];
      const Vec2& c = star[(k + 2) % n];
      convex = convex && (b - a).x() * (c - b).y() - (b - a).y() * (c - b).x() > 0.0;
    }
    non_convex += convex ? 0 : 1;
    const ObjectChecker checker(small, {Obstacle{1, star}});
    for (int q = 0; q < 50; ++q) {
      const Pose2 pose{-6.0 + 12.0 * unit(rng), -6.0 + 12.0 * unit(rng), 2.0 * kPi * unit(rng)};
      const auto corners = footprint_corners(small, pose);
      const Polygon box(corners.begin(), corners.end());
      const double expected = polygon_distance(box, star);
      const double got = checker.clearance(pose).distance;
      if (expected == 0.0) {
        EXPECT_LT(got, 1e-6) << "trial " << trial << " query " << q;
      } else {
        EXPECT_NEAR(got, expected, 1e-6) << "trial " << trial << " query " << q;
      }
      if (expected > 0.05 && got > 0.05) ++near_in_hull;
    }
  }
  EXPECT_GE(non_convex, 30);
  EXPECT_GT(near_in_hull, 100);
}

// A polygon whose edges cross has no agreed inside: its convex hull, which covers every reading.
TEST(ObjectChecker, APolygonWithCrossingEdgesIsCheckedAsItsHull) {
  const Obstacle bow_tie{2, {{8, -2}, {12, 2}, {12, -2}, {8, 2}}};
  const ObjectChecker checker(Footprint{0.5, 0.5, 0.5, 0.5}, {bow_tie});
  // (10, 1.5) lies between the two triangles of the bow tie, inside its hull (the box 8-12 x -2-2).
  EXPECT_DOUBLE_EQ(checker.clearance({10.0, 1.5, 0.0}).distance, 0.0);
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
