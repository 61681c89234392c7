// The path smoother: what it returns keeps the cusps and is drivable, by oracles independent of
// the smoother and of GridCollisionChecker (tests/planners/path_oracles.hpp): the footprint
// rectangle against every occupied cell of the grid the costmap was made from (each an exact
// square, separating axes) at every waypoint and every 2 cm between them, and the Menger
// curvature of consecutive points written in the oracle; and it refuses what it cannot keep free.
#include "pullout/freespace/path_smoother.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "../planners/path_oracles.hpp"
#include "pullout/freespace/hybrid_astar.hpp"
#include "pullout/geometry/angle.hpp"

namespace pullout {
namespace {

constexpr double kRes = 0.1;
constexpr int kThreshold = 50;
const Footprint kCar{3.79, 1.1, 0.95, 0.95};
constexpr double kTurningRadius = 5.2;

// A w x h metre occupancy grid (origin 0, 0) with a one-cell wall around it and the cells whose
// centre lies in one of the boxes (x0, y0, x1, y1) occupied.
OccupancyGrid grid_with_boxes(double w, double h, const std::vector<std::array<double, 4>>& boxes) {
  OccupancyGrid g;
  g.resolution_m = kRes;
  g.width = static_cast<std::uint32_t>(std::lround(w / kRes));
  g.height = static_cast<std::uint32_t>(std::lround(h / kRes));
  g.data.assign(static_cast<std::size_t>(g.width) * g.height, 0);
  for (std::uint32_t j = 0; j < g.height; ++j) {
    for (std::uint32_t i = 0; i < g.width; ++i) {
      const double x = (i + 0.5) * kRes;
      const double y = (j + 0.5) * kRes;
      bool occupied = i == 0 || j == 0 || i + 1 == g.width || j + 1 == g.height;
      for (const auto& b : boxes) occupied = occupied || (x > b[0] && x < b[2] && y > b[1] && y < b[3]);
      if (occupied) g.data[static_cast<std::size_t>(j) * g.width + i] = 100;
    }
  }
  return g;
}

PathWithLaneId as_segment(const std::vector<Waypoint>& w, std::size_t first, std::size_t last) {
  PathWithLaneId seg;
  for (std::size_t i = first; i <= last; ++i) {
    PathPoint p;
    p.pose = w[i].pose;
    seg.points.push_back(p);
  }
  return seg;
}

// Cusp indices (a waypoint after which the direction changes), the start and the end.
std::vector<std::size_t> fixed_points(const std::vector<Waypoint>& w) {
  std::vector<std::size_t> out{0};
  for (std::size_t i = 1; i + 1 < w.size(); ++i) {
    if (w[i + 1].direction != w[i].direction) out.push_back(i);
  }
  out.push_back(w.size() - 1);
  return out;
}

// Every pose of `w` and every 2 cm between them clear of the grid's occupied cells, and the
// curvature within each direction segment at most 1 / kTurningRadius.
void expect_drivable(const OccupancyGrid& grid, const std::vector<Waypoint>& w) {
  const std::vector<std::size_t> ends = fixed_points(w);
  for (std::size_t s = 0; s + 1 < ends.size(); ++s) {
    const PathWithLaneId seg = as_segment(w, ends[s], ends[s + 1]);
    for (const Pose2& pose : oracle::poses_along(seg, 0.02)) {
      ASSERT_FALSE(oracle::overlaps_grid(grid, kThreshold, oracle::rectangle_at(kCar, pose)))
          << "segment " << s << " at (" << pose.x << ", " << pose.y << ", " << pose.yaw << ")";
    }
    for (std::size_t i = 1; i + 1 < seg.points.size(); ++i) {
      const double k = oracle::menger_curvature(to_vec(seg.points[i - 1].pose), to_vec(seg.points[i].pose),
                                                to_vec(seg.points[i + 1].pose));
      EXPECT_LE(std::abs(k), 1.0 / kTurningRadius * (1.0 + 1e-6)) << "segment " << s << " point " << i;
    }
  }
}

TEST(PathSmoother, OutOfABayKeepsTheCuspsAndStaysDrivable) {
  // Nose-in in a bay between two parked cars, out to the aisle heading east: hybrid A* reverses
  // out (at least one cusp).
  const OccupancyGrid grid =
      grid_with_boxes(30, 20, {{6.5, 0.2, 8.4, 5.2}, {10.9, 0.2, 12.8, 5.2}, {0, 14, 30, 20}, {15, 0, 16, 10.5}});
  const Costmap costmap = Costmap::from_occupancy_grid(grid, kThreshold);
  const GridCollisionChecker checker(costmap, kCar);
  HybridAStarConfig search;
  search.turning_radius = kTurningRadius;
  const HybridAStarResult r =
      HybridAStar(checker, search).plan({9.65, 4.2, -kPi / 2}, {21, 4, -kPi / 2}, StopCondition::after_ms(5000));
  ASSERT_EQ(r.status, HybridAStarResult::Status::kSuccess);
  const std::vector<std::size_t> cusps = fixed_points(r.waypoints);
  ASSERT_GE(cusps.size(), 3u) << "the start, a cusp, the end";

  PathSmootherConfig config;
  config.max_curvature = 1.0 / kTurningRadius;
  const SmoothedPath s = smooth_path(r.waypoints, checker, config);
  ASSERT_EQ(s.waypoints.size(), r.waypoints.size());
  EXPECT_EQ(s.segments, static_cast<int>(cusps.size()) - 1);
  EXPECT_GE(s.smoothed, 1);
  for (std::size_t i = 0; i < s.waypoints.size(); ++i) {
    EXPECT_EQ(s.waypoints[i].direction, r.waypoints[i].direction) << i;
  }
  for (std::size_t i : cusps) {
    // Unchanged bit for bit: the segments still join and the vehicle stops where it was planned.
    EXPECT_EQ(s.waypoints[i].pose.x, r.waypoints[i].pose.x) << i;
    EXPECT_EQ(s.waypoints[i].pose.y, r.waypoints[i].pose.y) << i;
    EXPECT_EQ(s.waypoints[i].pose.yaw, r.waypoints[i].pose.yaw) << i;
  }
  expect_drivable(grid, s.waypoints);
  // Smoother: the steering moves less (the oracle's own curvature; the energy sum of dk^2 / ds
  // over the segments: a step in curvature is large, a ramp small).
  const auto energy = [&](const std::vector<Waypoint>& w) {
    double sum = 0.0;
    for (std::size_t c = 0; c + 1 < cusps.size(); ++c) {
      double previous = 0.0;
      for (std::size_t i = cusps[c] + 1; i < cusps[c + 1]; ++i) {
        const double k = oracle::menger_curvature(to_vec(w[i - 1].pose), to_vec(w[i].pose), to_vec(w[i + 1].pose));
        const double ds = std::hypot(w[i].pose.x - w[i - 1].pose.x, w[i].pose.y - w[i - 1].pose.y);
        if (i > cusps[c] + 1) sum += (k - previous) * (k - previous) / ds;
        previous = k;
      }
    }
    return sum;
  };
  EXPECT_LT(energy(s.waypoints), energy(r.waypoints));
}

// A forward segment along y = 5 with a bump of radius `radius` (left, right twice, left: each
// arc turning by `angle`), waypoints every 0.25 m.
std::vector<Waypoint> bump_path(double radius, double angle) {
  std::vector<Waypoint> w;
  Pose2 pose{3.0, 5.0, 0.0};
  const auto drive = [&](double length, double curvature) {
    const int n = static_cast<int>(std::ceil(length / 0.25 - 1e-9));
    const double ds = length / n;
    for (int k = 0; k < n; ++k) {
      if (std::abs(curvature) < 1e-12) {
        pose = {pose.x + ds * std::cos(pose.yaw), pose.y + ds * std::sin(pose.yaw), pose.yaw};
      } else {
        const double yaw = pose.yaw + ds * curvature;
        pose = {pose.x + (std::sin(yaw) - std::sin(pose.yaw)) / curvature,
                pose.y - (std::cos(yaw) - std::cos(pose.yaw)) / curvature, yaw};
      }
      w.push_back({pose, 1});
    }
  };
  w.push_back({pose, 1});
  drive(2.0, 0.0);
  drive(radius * angle, 1.0 / radius);
  drive(2.0 * radius * angle, -1.0 / radius);
  drive(radius * angle, 1.0 / radius);
  drive(2.0, 0.0);
  return w;
}

// The least distance [m] from the body along `w` (every 2 cm) to `post` (oracle polygons).
double least_distance(const std::vector<Waypoint>& w, const Polygon& post) {
  double d = 1e9;
  for (const Pose2& pose : oracle::poses_along(as_segment(w, 0, w.size() - 1), 0.02)) {
    d = std::min(d, oracle::polygon_distance(oracle::rectangle_at(kCar, pose), post));
  }
  return d;
}

Polygon post_at(double x, double y0, double y1) {
  return {{x - 0.05, y0}, {x + 0.05, y0}, {x + 0.05, y1}, {x - 0.05, y1}};
}

TEST(PathSmoother, RefusesWhatItCannotProveFree) {
  // The bump passes 3 mm above a post at its top (placed by the oracle's polygon distance): free,
  // but closer than the smoother's check can prove (an eighth of a cell, 12.5 mm), and the
  // smoothed bump comes down there. The smoother must return the input unchanged rather than a
  // path it has not proven free.
  const std::vector<Waypoint> input = bump_path(2.0 * kTurningRadius, 0.3);
  double top = 0.0;
  std::size_t top_index = 0;
  for (std::size_t i = 0; i < input.size(); ++i) {
    if (input[i].pose.y > top) {
      top = input[i].pose.y;
      top_index = i;
    }
  }
  const double x = input[top_index].pose.x;
  // Bisection on the post's top edge: far (1.5 m below) and touching (5 cm into the body) at first.
  double far = top - kCar.right - 1.5;
  double near = top - kCar.right + 0.05;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (far + near);
    (least_distance(input, post_at(x, mid - 1.0, mid)) > 3e-3 ? far : near) = mid;
  }
  const std::vector<Polygon> posts{post_at(x, far - 1.0, far)};
  ASSERT_NEAR(least_distance(input, posts[0]), 3e-3, 1e-5);
  Aabb extent;
  extent.extend({0.0, 0.0});
  extent.extend({30.0, 12.0});
  const Polygon all{{0, 0}, {30, 0}, {30, 12}, {0, 12}};
  const Costmap costmap = Costmap::from_polygons(extent, kRes, {all}, {}, posts);
  const GridCollisionChecker checker(costmap, kCar);

  PathSmootherConfig config;
  config.max_curvature = 1.0 / kTurningRadius;
  const SmoothedPath s = smooth_path(input, checker, config);
  EXPECT_EQ(s.segments, 1);
  EXPECT_EQ(s.smoothed, 0);
  ASSERT_EQ(s.waypoints.size(), input.size());
  for (std::size_t i = 0; i < input.size(); ++i) {
    EXPECT_EQ(s.waypoints[i].pose.x, input[i].pose.x) << i;
    EXPECT_EQ(s.waypoints[i].pose.y, input[i].pose.y) << i;
    EXPECT_EQ(s.waypoints[i].pose.yaw, input[i].pose.yaw) << i;
  }

  // The same bump with the post half a metre lower: smoothed, and clear of the post by the oracle.
  const std::vector<Polygon> lower{post_at(x, far - 1.5, far - 0.5)};
  const Costmap open = Costmap::from_polygons(extent, kRes, {all}, {}, lower);
  const GridCollisionChecker open_checker(open, kCar);
  const SmoothedPath t = smooth_path(input, open_checker, config);
  EXPECT_EQ(t.smoothed, 1);
  EXPECT_EQ(t.refused, 0);
  EXPECT_GT(least_distance(t.waypoints, lower[0]), 0.0);
  EXPECT_LT(path_shape(t.waypoints).curvature_energy, path_shape(input).curvature_energy);
}

TEST(PathSmoother, ThreePointCurvatureIsOneOverTheRadiusOnACircle) {
  const double r = 4.0;
  const Vec2 a{r * std::cos(0.1), r * std::sin(0.1)};
  const Vec2 b{r * std::cos(0.3), r * std::sin(0.3)};
  const Vec2 c{r * std::cos(0.35), r * std::sin(0.35)};
  EXPECT_NEAR(three_point_curvature(a, b, c), 1.0 / r, 1e-12);   // counter-clockwise: left
  EXPECT_NEAR(three_point_curvature(c, b, a), -1.0 / r, 1e-12);  // clockwise: right
  EXPECT_EQ(three_point_curvature({0, 0}, {1, 0}, {2, 0}), 0.0);
}

}  // namespace
}  // namespace pullout
