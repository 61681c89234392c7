#include "pullout/lane_planners/two_turn_path.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "pullout/config/scenario.hpp"
#include "pullout/geometry/angle.hpp"
#include "pullout/geometry/curvature_path.hpp"
#include "pullout/model/types.hpp"
#include "pullout/pipeline/start_planner.hpp"
#include "test_world.hpp"

namespace pullout {
namespace {

Polyline straight_centerline() { return Polyline({{-10.0, 0.0}, {100.0, 0.0}}).resampled(1.0); }

// Menger curvature of consecutive samples.
double max_sampled_curvature(const std::vector<Pose2>& poses) {
  double k = 0.0;
  for (std::size_t i = 1; i + 1 < poses.size(); ++i) {
    const Vec2 a = to_vec(poses[i - 1]);
    const Vec2 b = to_vec(poses[i]);
    const Vec2 c = to_vec(poses[i + 1]);
    const double cross = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
    const double denom = (b - a).norm() * (c - b).norm() * (c - a).norm();
    if (denom > 1e-12) k = std::max(k, std::abs(2.0 * cross / denom));
  }
  return k;
}

TEST(CurvaturePath, ArcEndsWhereGeometrySays) {
  // A quarter circle of radius 5 to the left from the origin ends at (5, 5) facing +y.
  const CurvaturePath arc({0.0, 0.0, 0.0}, {{5.0 * kPi / 2.0, 0.2, 0.2}});
  EXPECT_NEAR(arc.end().x, 5.0, 1e-12);
  EXPECT_NEAR(arc.end().y, 5.0, 1e-12);
  EXPECT_NEAR(arc.end().yaw, kPi / 2.0, 1e-12);
}

TEST(CurvaturePath, ClothoidIntegrationMatchesAFineEulerReference) {
  const CurvaturePiece piece{3.0, 0.0, 0.3};
  const Pose2 end = CurvaturePath::advance({1.0, 2.0, 0.4}, piece, piece.length);
  // Reference: 300,000 midpoint steps.
  double x = 1.0, y = 2.0;
  const int n = 300000;
  const double h = piece.length / n;
  for (int i = 0; i < n; ++i) {
    const double s = (i + 0.5) * h;
    const double th = 0.4 + 0.5 * (0.3 / 3.0) * s * s;
    x += h * std::cos(th);
    y += h * std::sin(th);
  }
  // Simpson with 16 intervals over 0.45 rad of heading change: within a micrometre.
  EXPECT_NEAR(end.x, x, 1e-6);
  EXPECT_NEAR(end.y, y, 1e-6);
  EXPECT_NEAR(end.yaw, 0.4 + 0.45, 1e-12);
}

TEST(TwoTurnPath, ArcSCurveMatchesTheWorkedExample) {
  // Reference facts 2.2: d = 3.5 m, R = 5.06 m -> each arc turns acos(1 - d / 2R) (about 49 deg),
  // 4.34 m of arc each, the end 7.65 m ahead.
  const double R = 5.06;
  const auto t = solve_two_turn({0.0, 3.5, 0.0}, straight_centerline(), {1.0 / R, 0.0, 0.0});
  ASSERT_TRUE(t.has_value());
  const double theta = std::acos(1.0 - 3.5 / (2.0 * R));
  ASSERT_EQ(t->path.pieces().size(), 2u);
  EXPECT_NEAR(t->path.pieces()[0].length, R * theta, 1e-3);
  EXPECT_NEAR(t->path.pieces()[0].length, 4.34, 0.01);
  EXPECT_NEAR(t->path.end().x, 2.0 * R * std::sin(theta), 1e-3);
  EXPECT_NEAR(t->path.end().y, 0.0, 1e-3);
  EXPECT_NEAR(t->path.end().yaw, 0.0, 1e-9);
}

TEST(ArcPair, ReachesTheEndPoseWithTheRadiiOfTheWorkedFormula) {
  // Parallel start d below the centerline, end L ahead on it: the S of two tangent arcs turns by
  // the same angle t both ways, (R1 + R2)(1 - cos t) = d and (R1 + R2) sin t = L, so
  // R1 + R2 = (L^2 + d^2) / (2 d).
  const double d = 3.5;
  const double r1 = 5.06;
  for (double length : {7.65, 9.0, 12.0, 16.65}) {
    const auto t = solve_arc_pair({0.0, -d, 0.0}, {length, 0.0, 0.0}, r1, r1 * 0.99);
    ASSERT_TRUE(t.has_value()) << length;
    ASSERT_EQ(t->path.pieces().size(), 2u);
    EXPECT_EQ(t->first_turn_pieces, 1u);
    const auto& arcs = t->path.pieces();
    EXPECT_NEAR(1.0 / arcs[0].k0, r1, 1e-12);  // turns left first, at R1
    const double r2 = -1.0 / arcs[1].k0;       // then right
    EXPECT_NEAR(r1 + r2, (length * length + d * d) / (2.0 * d), 1e-9) << length;
    const double turn = std::asin(length / (r1 + r2));
    EXPECT_NEAR(arcs[0].length, r1 * turn, 1e-9);
    EXPECT_NEAR(arcs[1].length, r2 * turn, 1e-9);
    EXPECT_NEAR(t->path.end().x, length, 1e-9);
    EXPECT_NEAR(t->path.end().y, 0.0, 1e-9);
    EXPECT_NEAR(t->path.end().yaw, 0.0, 1e-9);
  }
  // Mirrored: start above the centerline turns right first.
  const auto m = solve_arc_pair({0.0, d, 0.0}, {12.0, 0.0, 0.0}, r1, r1);
  ASSERT_TRUE(m.has_value());
  EXPECT_LT(m->path.pieces()[0].k0, 0.0);
  // An end closer than two arcs of R1 allow needs R2 < R1: refused below the minimum radius.
  EXPECT_FALSE(solve_arc_pair({0.0, -d, 0.0}, {6.0, 0.0, 0.0}, r1, r1).has_value());
  // Facing across the road, farther than R1 from the centerline (out of a perpendicular bay):
  // the first arc's circle and any second one tangent to the centerline at the end cannot touch
  // (|C1 - C2|^2 = (R1 + R2)^2 needs (R1 - 8)^2 + (6 + R2)^2 = (R1 + R2)^2, i.e. R2 < 0).
  EXPECT_FALSE(solve_arc_pair({0.0, 6.0, -kPi / 2}, {8.0, 0.0, 0.0}, r1, r1).has_value());
}

TEST(ArcPair, TurnsTowardsTheRoadFirstWhenAskedWhereTheEndLiesOnTheKerbSideOfTheHeading) {
  // An S built forward: left by 0.4 rad at R1 (towards a road on the left), then right by 0.92 rad
  // at R2 = 9.5 m; it ends turned 0.52 rad to the right and 0.106 m right of the start's heading
  // line (a start turned towards the road, the road bending back; Autoware's shoulders 10988 and
  // 10992). Asked to turn left first, the solver finds exactly that S again.
  const double r1 = 5.06;
  const double r2 = 9.5;
  const double a = 0.4;
  const double b = 0.92;
  const Vec2 tangent{r1 * std::sin(a), r1 * (1.0 - std::cos(a))};
  const Vec2 c2 = tangent + r2 * Vec2{std::sin(a), -std::cos(a)};
  const Pose2 end{c2.x() - r2 * std::sin(a - b), c2.y() + r2 * std::cos(a - b), a - b};
  ASSERT_LT(end.y, 0.0);  // right of the heading line: on its own, the solver turns right first
  const auto t = solve_arc_pair({0.0, 0.0, 0.0}, end, r1, r1, 1.0);
  ASSERT_TRUE(t.has_value());
  const auto& arcs = t->path.pieces();
  ASSERT_EQ(arcs.size(), 2u);
  EXPECT_NEAR(1.0 / arcs[0].k0, r1, 1e-12);
  EXPECT_NEAR(-1.0 / arcs[1].k0, r2, 1e-9);
  EXPECT_NEAR(arcs[0].length, r1 * a, 1e-9);
  EXPECT_NEAR(arcs[1].length, r2 * b, 1e-9);
  EXPECT_NEAR(t->path.end().x, end.x, 1e-6);
  EXPECT_NEAR(t->path.end().y, end.y, 1e-6);
  // Without the side, the first arc turns right (towards where the end lies), not this S.
  const auto own = solve_arc_pair({0.0, 0.0, 0.0}, end, r1, r1);
  EXPECT_TRUE(!own.has_value() || own->path.pieces()[0].k0 < 0.0);
}

TEST(TwoTurnPath, ClothoidTurnsStayWithinTheirPeakCurvature) {
  const VehicleInfo v;
  for (double steer_deg : {5.0, 10.0, 20.0, 30.0}) {
    const double steer = steer_deg * kDegToRad;
    const double kappa = std::tan(steer) / v.wheel_base_m;
    const double clothoid_length = 1.0 * steer / (10.0 * kDegToRad);
    for (double offset : {0.3, 1.0, 3.25, 6.0}) {
      const auto t = solve_two_turn({0.0, offset, 0.0}, straight_centerline(), {kappa, kappa / clothoid_length, 0.0});
      ASSERT_TRUE(t.has_value()) << steer_deg << " deg, offset " << offset;
      const auto& pieces = t->path.pieces();
      // Curvature is continuous: starts and ends at 0, each piece starts where the last ended.
      EXPECT_DOUBLE_EQ(pieces.front().k0, 0.0);
      EXPECT_DOUBLE_EQ(pieces.back().k1, 0.0);
      for (std::size_t i = 1; i < pieces.size(); ++i) EXPECT_NEAR(pieces[i].k0, pieces[i - 1].k1, 1e-12);
      EXPECT_LE(t->path.max_abs_curvature(), kappa + 1e-12);
      // Sampled every 5 cm the geometry agrees (1 % for the discrete estimate).
      EXPECT_LE(max_sampled_curvature(t->path.sample(0.05)), kappa * 1.01) << steer_deg << " deg, offset " << offset;
      EXPECT_LE(kappa, 1.0 / v.min_turning_radius_m());
      EXPECT_NEAR(t->path.end().y, 0.0, 1e-3);
    }
  }
}

TEST(TwoTurnPath, PerpendicularStartTurnsOntoTheLane) {
  // Facing -y, 6 m left of the centerline: turns left by 90 degrees in total.
  const auto t = solve_two_turn({0.0, 6.0, -kPi / 2.0}, straight_centerline(), {0.2, 0.0, 1.0});
  ASSERT_TRUE(t.has_value());
  EXPECT_NEAR(t->path.end().y, 0.0, 1e-3);
  EXPECT_NEAR(t->path.end().yaw, 0.0, 1e-3);
  EXPECT_GT(t->path.end().x, 0.0);
}

TEST(TwoTurnPath, NoSolutionWhenTheTurnsCannotReachTheCenterline) {
  // 20 m to the side with arcs of radius 5 and no tangent: 2R(1 - cos d) <= 10 m < 20 m.
  EXPECT_FALSE(solve_two_turn({0.0, 20.0, 0.0}, straight_centerline(), {0.2, 0.0, 0.0}).has_value());
}

TEST(SearchPolicy, OrdersTheAttemptsInsideAMargin) {
  // full_search: every (candidate, planner) pair fails, so each is tried at every margin.
  const Scenario sc = load_scenario(std::string(PULLOUT_SOURCE_DIR) + "/tests/scenarios/full_search.yaml");
  const auto first_margin_rows = [&](SearchPolicy policy) {
    StartPlannerParameters p = sc.parameters;
    p.search_policy = policy;
    PullOutRequest req = sc.request;
    req.overrides = {};
    std::vector<std::pair<PlannerType, double>> out;
    for (const auto& a : StartPlanner(sc.vehicle, p).plan(req, StopCondition()).evaluation_table) {
      if (a.planner != PlannerType::kNone && a.margin_m == p.collision_check_margins.front()) {
        out.emplace_back(a.planner, a.backward_distance_m);
      }
    }
    return out;
  };
  const auto planner_first = first_margin_rows(SearchPolicy::kPlannerPriority);
  const auto distance_first = first_margin_rows(SearchPolicy::kDistancePriority);
  const std::size_t planners = sc.parameters.search_priority.size();
  ASSERT_EQ(planners, 3u);
  ASSERT_EQ(planner_first.size(), 33u);  // 11 candidates x 3 planners
  ASSERT_EQ(distance_first.size(), 33u);
  const std::size_t candidates = planner_first.size() / planners;
  for (std::size_t i = 0; i < planner_first.size(); ++i) {
    // planner_priority: every candidate with the first planner, then with the second, ...
    EXPECT_EQ(planner_first[i].first, sc.parameters.search_priority[i / candidates]) << i;
    EXPECT_DOUBLE_EQ(planner_first[i].second, 2.0 * static_cast<double>(i % candidates)) << i;
    // distance_priority: every planner at the nearest candidate, then at the next, ...
    EXPECT_EQ(distance_first[i].first, sc.parameters.search_priority[i % planners]) << i;
    EXPECT_DOUBLE_EQ(distance_first[i].second, 2.0 * static_cast<double>(i / planners)) << i;
  }
}

}  // namespace
}  // namespace pullout
