// Reeds-Shepp curves. Oracle: driving every returned word segment by segment (independent
// integration of the arcs, 2 mm steps) must end at the goal; lengths obey the metric's properties.
#include "pullout/freespace/reeds_shepp.hpp"
#include "pullout/geometry/angle.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>
#include <string>

namespace pullout {
namespace {

// Small-step numerical integration of a word (the oracle: no closed forms involved).
Pose2 integrate(const Pose2& from, const ReedsSheppPath& p, double radius) {
  Pose2 q = from;
  for (int i = 0; i < p.count; ++i) {
    const auto& seg = p.segments[static_cast<std::size_t>(i)];
    const double k = static_cast<double>(static_cast<int>(seg.kind)) / radius;
    const int n = std::max(1, static_cast<int>(std::abs(seg.length) / 2e-3));
    const double ds = seg.length / n;
    for (int s = 0; s < n; ++s) {
      // Midpoint rule on the heading: exact for straight lines, second order on arcs.
      const double mid = q.yaw + 0.5 * k * ds;
      q.x += ds * std::cos(mid);
      q.y += ds * std::sin(mid);
      q.yaw += k * ds;
    }
  }
  return q;
}

double angle_diff(double a, double b) { return std::remainder(a - b, 2.0 * kPi); }

std::string word(const ReedsSheppPath& p) {
  std::string w;
  for (int i = 0; i < p.count; ++i) {
    const auto& s = p.segments[static_cast<std::size_t>(i)];
    w += s.kind == ReedsSheppSegment::Kind::kLeft ? 'L' : (s.kind == ReedsSheppSegment::Kind::kRight ? 'R' : 'S');
    w += s.length >= 0.0 ? '+' : '-';
  }
  return w;
}

TEST(ReedsShepp, EveryWordReachesTheGoal) {
  const double radius = 4.0;
  const ReedsShepp rs(radius);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> pos(-15.0, 15.0), yaw(-kPi, kPi);
  std::set<int> counts;
  std::set<std::string> shortest_words;
  for (int n = 0; n < 200; ++n) {
    const Pose2 a{pos(rng), pos(rng), yaw(rng)};
    const Pose2 b{pos(rng), pos(rng), yaw(rng)};
    const auto words = rs.all(a, b);
    ASSERT_FALSE(words.empty());
    double best = 1e300;
    for (const auto& w : words) {
      const Pose2 end = integrate(a, w, radius);
      ASSERT_NEAR(end.x, b.x, 1e-4) << word(w);
      ASSERT_NEAR(end.y, b.y, 1e-4) << word(w);
      ASSERT_NEAR(angle_diff(end.yaw, b.yaw), 0.0, 1e-6) << word(w);
      const Pose2 closed = rs.interpolate(a, w, w.length);
      EXPECT_NEAR(closed.x, b.x, 1e-6);
      EXPECT_NEAR(closed.y, b.y, 1e-6);
      counts.insert(w.count);
      best = std::min(best, w.length);
    }
    const ReedsSheppPath s = rs.shortest(a, b);
    shortest_words.insert(word(s));
    EXPECT_DOUBLE_EQ(s.length, best);
    EXPECT_DOUBLE_EQ(rs.distance(a, b), best);
    EXPECT_GE(best, std::hypot(b.x - a.x, b.y - a.y) - 1e-9);
    // The metric is symmetric: a path from b to a is the path from a to b driven backwards.
    EXPECT_NEAR(rs.distance(b, a), best, 1e-9);
  }
  // Every family appears: 3 (CSC, CCC), 4 (CCCC, CCSC) and 5 (CCSCC) segments.
  EXPECT_EQ(counts, (std::set<int>{3, 4, 5}));
  EXPECT_GT(shortest_words.size(), 10u);
}

TEST(ReedsShepp, StraightAheadAndBehind) {
  const ReedsShepp rs(5.0);
  EXPECT_NEAR(rs.distance({0, 0, 0}, {7, 0, 0}), 7.0, 1e-9);
  EXPECT_NEAR(rs.distance({0, 0, 0}, {-7, 0, 0}), 7.0, 1e-9);
  const ReedsSheppPath back = rs.shortest({0, 0, 0}, {-7, 0, 0});
  EXPECT_NEAR(back.reverse_length(), 7.0, 1e-9);
  EXPECT_EQ(back.cusps(), 0);
  EXPECT_NEAR(rs.distance({1, 2, 0.3}, {1, 2, 0.3}), 0.0, 1e-12);
}

TEST(ReedsShepp, QuarterTurnIsOneArc) {
  const double r = 5.0;
  const ReedsShepp rs(r);
  // A left quarter circle: from (0, 0, 0) to (r, r, pi/2).
  EXPECT_NEAR(rs.distance({0, 0, 0}, {r, r, kPi / 2}), r * kPi / 2, 1e-9);
  // Turning on the spot by pi needs cusps and is longer than the half circle around.
  const ReedsSheppPath turn = rs.shortest({0, 0, 0}, {0, 0, kPi});
  EXPECT_GT(turn.cusps(), 0);
  EXPECT_GT(turn.length, 0.0);
}

TEST(ReedsShepp, InterpolateStartsAndStepsAlongThePath) {
  const ReedsShepp rs(3.0);
  const Pose2 a{0, 0, 0};
  const Pose2 b{-2, 4, 2.0};
  const ReedsSheppPath p = rs.shortest(a, b);
  const Pose2 s0 = rs.interpolate(a, p, 0.0);
  EXPECT_NEAR(s0.x, 0.0, 1e-12);
  // Consecutive samples 1 cm apart are at most 1 cm apart.
  Pose2 last = s0;
  for (double s = 0.01; s <= p.length; s += 0.01) {
    const Pose2 q = rs.interpolate(a, p, s);
    EXPECT_LE(std::hypot(q.x - last.x, q.y - last.y), 0.01 + 1e-9);
    last = q;
  }
}

}  // namespace
}  // namespace pullout
