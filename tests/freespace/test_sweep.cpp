// The swept-motion checks of the hybrid A* (search_support.hpp): what they accept is free at
// every pose, not only at the poses they test, and driving until contact gets close to the
// contact. Oracle: the exact footprint test of the checker
// (itself tested against brute force and polygon oracles in test_costmap / test_exact_obstacles)
// at poses 2.5 mm apart along the arc, far denser than the tests under check.
#include "search_support.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "pullout/geometry/angle.hpp"

namespace pullout {
namespace {

namespace fd = freespace_detail;

constexpr double kRes = 0.1;
constexpr double kRadius = 3.0;  // [m] a tight turning radius: large heading changes per arc
constexpr int kOracleSamples = 200;

// A 20 m x 20 m map at 0.1 m with 30 small boxes at random poses: many arcs graze an obstacle.
Costmap cluttered_map(std::mt19937& rng) {
  std::vector<Polygon> boxes;
  std::uniform_real_distribution<double> pos(2.0, 18.0);
  std::uniform_real_distribution<double> yaw(-kPi, kPi);
  std::uniform_real_distribution<double> side(0.05, 0.5);
  for (int i = 0; i < 30; ++i) {
    const double cx = pos(rng);
    const double cy = pos(rng);
    const double a = yaw(rng);
    const double hl = side(rng);
    const double hw = side(rng);
    const Vec2 u(std::cos(a), std::sin(a));
    const Vec2 v(-u.y(), u.x());
    const Vec2 c(cx, cy);
    boxes.push_back({c - hl * u - hw * v, c + hl * u - hw * v, c + hl * u + hw * v, c - hl * u + hw * v});
  }
  const int n = static_cast<int>(std::round(20.0 / kRes));
  Costmap m({}, kRes, n, n, std::vector<std::uint8_t>(static_cast<std::size_t>(n) * n, 0));
  m.add_obstacles(boxes);
  return m;
}

const Footprint kCar{3.76, 0.929, 0.971, 0.971};  // the TPCAP car (rear-axle frame)

// The first pose along the arc (of kOracleSamples + 1) that collides, or -1.
int first_collision(const GridCollisionChecker& checker, const Pose2& from, double curvature, double distance) {
  for (int i = 0; i <= kOracleSamples; ++i) {
    if (checker.collides(fd::drive(from, curvature, distance * i / kOracleSamples))) return i;
  }
  return -1;
}

TEST(SweptMotion, AnArcArcFreeAcceptsIsFreeAtEveryPose) {
  std::mt19937 rng(7);
  const Costmap m = cluttered_map(rng);
  const GridCollisionChecker checker(m, kCar);
  std::uniform_real_distribution<double> pos(1.0, 19.0);
  std::uniform_real_distribution<double> yaw(-kPi, kPi);
  std::uniform_int_distribution<int> steer(-1, 1);
  int accepted = 0;
  int refused = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const Pose2 start{pos(rng), pos(rng), yaw(rng)};
    double start_clearance = 0.0;
    if (checker.collides(start, start_clearance)) continue;
    const double k = steer(rng) / kRadius;
    const double d = (trial % 2 == 0 ? 1.0 : -1.0) * 0.5;
    double end_clearance = 0.0;
    if (!fd::arc_free(checker, fd::Arc(start, k), start_clearance, d, end_clearance)) {
      ++refused;
      continue;
    }
    ++accepted;
    ASSERT_EQ(first_collision(checker, start, k, d), -1)
        << "accepted arc from (" << start.x << ", " << start.y << ", " << start.yaw << ") k " << k << " d " << d;
  }
  // Both outcomes occur often, or the property was not exercised.
  EXPECT_GT(accepted, 500);
  EXPECT_GT(refused, 500);
}

// The search takes a free primitive's end pose from arc_free instead of driving the arc again:
// it must be the very pose the test used and the arc's own end, with the same answer and clearance.
TEST(SweptMotion, TheEndPoseArcFreeGivesIsTheArcsEnd) {
  std::mt19937 rng(5);
  const Costmap m = cluttered_map(rng);
  const GridCollisionChecker checker(m, kCar);
  std::uniform_real_distribution<double> pos(1.0, 19.0);
  std::uniform_real_distribution<double> yaw(-kPi, kPi);
  std::uniform_int_distribution<int> steer(-1, 1);
  int accepted = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const Pose2 start{pos(rng), pos(rng), yaw(rng)};
    double start_clearance = 0.0;
    if (checker.collides(start, start_clearance)) continue;
    const fd::Arc arc(start, steer(rng) / kRadius);
    const double d = (trial % 2 == 0 ? 1.0 : -1.0) * 0.5;
    double plain_clearance = 0.0;
    double clearance = 0.0;
    Pose2 end{-1.0, -1.0, -1.0};
    const bool plain = fd::arc_free(checker, arc, start_clearance, d, plain_clearance);
    ASSERT_EQ(fd::arc_free(checker, arc, start_clearance, d, clearance, end), plain);
    if (!plain) continue;
    ++accepted;
    const Pose2 expected = arc.at(d);
    EXPECT_EQ(end.x, expected.x);
    EXPECT_EQ(end.y, expected.y);
    EXPECT_EQ(end.yaw, expected.yaw);
    EXPECT_EQ(clearance, plain_clearance);
  }
  EXPECT_GT(accepted, 100);
}

// The hull tests take each pose's cos and sin of its heading from Arc::at instead of computing
// them from the pose's yaw: they must be the very values std::cos and std::sin give for that yaw,
// or the hulls (and so the search's answers) would change.
TEST(SweptMotion, TheHeadingsCosAndSinFromTheArcAreThoseOfThePosesYaw) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> yaw(-4.0 * kPi, 4.0 * kPi);
  std::uniform_real_distribution<double> distance(-3.0, 3.0);
  std::uniform_int_distribution<int> steer(-2, 2);
  for (int trial = 0; trial < 20000; ++trial) {
    const Pose2 start{1.0, 2.0, yaw(rng)};
    const fd::Arc arc(start, steer(rng) / kRadius);
    double c = 0.0;
    double s = 0.0;
    const Pose2 p = arc.at(distance(rng), c, s);
    ASSERT_EQ(c, std::cos(p.yaw)) << "yaw " << p.yaw;
    ASSERT_EQ(s, std::sin(p.yaw)) << "yaw " << p.yaw;
  }
}

TEST(SweptMotion, DrivingUntilContactStopsBeforeTheFirstCollisionAndNotFarBeforeIt) {
  std::mt19937 rng(11);
  const Costmap m = cluttered_map(rng);
  const GridCollisionChecker checker(m, kCar);
  // "Not far before it": the hull tests are conservative by ~1 cm (search_support.hpp), so a
  // motion is only owed as far as the body grown by kGrazing stays free, less kSlack (the sample
  // spacing, a cell of body motion <= 0.1 m, and the bisection's 1/32 of the interval).
  constexpr double kGrazing = 0.02;  // [m]
  constexpr double kSlack = 0.15;    // [m]
  const GridCollisionChecker roomy(
      m, Footprint{kCar.front + kGrazing, kCar.rear + kGrazing, kCar.left + kGrazing, kCar.right + kGrazing});
  std::uniform_real_distribution<double> pos(1.0, 19.0);
  std::uniform_real_distribution<double> yaw(-kPi, kPi);
  std::uniform_int_distribution<int> steer(-1, 1);
  constexpr double kMin = 0.05;  // [m] shortest prefix asked for
  constexpr double kDistance = 1.0;
  int cut = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const Pose2 start{pos(rng), pos(rng), yaw(rng)};
    double start_clearance = 0.0;
    if (checker.collides(start, start_clearance)) continue;
    const double k = steer(rng) / kRadius;
    const double d = (trial % 2 == 0 ? 1.0 : -1.0) * kDistance;
    const double free = fd::free_prefix(checker, fd::Arc(start, k), start_clearance, d, kMin);
    const std::string where = "from (" + std::to_string(start.x) + ", " + std::to_string(start.y) + ", " +
                              std::to_string(start.yaw) + ") k " + std::to_string(k) + " d " + std::to_string(d);
    if (free > 0.0) {
      ASSERT_GE(free, kMin) << where;
      ASSERT_EQ(first_collision(checker, start, k, std::copysign(free, d)), -1) << where << " prefix " << free;
    }
    const int hit = first_collision(roomy, start, k, d);
    const double owed = hit < 0 ? kDistance : kDistance * (hit - 1) / kOracleSamples;  // last free sample
    if (owed >= kMin + kSlack) ASSERT_GE(free, owed - kSlack) << where << " owed " << owed;
    cut += hit >= 0 && free > 0.0 ? 1 : 0;
  }
  EXPECT_GT(cut, 300);  // arcs that do come close and were driven part of the way: the case under test
}

// sweep_collides grows each piece's hull by the margin, moving a vertex out along its bisector by
// up to margin x sqrt 2 (a right-angled corner). Its pre-test of the corners' box must cover that
// much: a 2 m x 1 m body turned 45 degrees, whose front-left corner's bisector points straight
// up, and one occupied cell just below the grown vertex's tip (margin sqrt 2 = 0.42 m above the
// corner, the cell from 0.40 m to 0.50 m) collides; the cell above it does not. A pre-test box
// grown by the margin only (0.30 m) would call the first motion free.
TEST(SweptMotion, HullGrownByTheMarginReachesPastTheCornersBox) {
  const Footprint body{1.0, 1.0, 0.5, 0.5};
  constexpr double kMargin = 0.3;
  const double c = std::sqrt(0.5);
  // The front-left corner (1.0, 0.5) in the body frame lands at (5.05, 5.0): column 50's centre.
  const Pose2 pose{5.05 - (1.0 * c - 0.5 * c), 5.0 - (1.0 * c + 0.5 * c), kPi / 4};
  for (const int row : {54, 55}) {
    std::vector<std::uint8_t> cells(100 * 100, 0);
    cells[static_cast<std::size_t>(row) * 100 + 50] = 1;
    const Costmap map({}, kRes, 100, 100, cells);
    const GridCollisionChecker checker(map, body);
    ASSERT_FALSE(checker.collides(pose));
    EXPECT_EQ(checker.sweep_collides(pose, pose, kMargin), row == 54) << "occupied row " << row;
  }
}

}  // namespace
}  // namespace pullout
