#include "pullout/planners/shift_pull_out.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "pullout/geometry/polyline.hpp"
#include "pullout/pipeline/start_planner.hpp"
#include "test_world.hpp"

namespace pullout {
namespace {

// ---- formulas against the worked numbers of the reference facts (section 2.1) ----
// The table gives 2 decimals, so 0.006 covers its rounding and nothing more.
constexpr double kTableTolerance = 0.006;

TEST(ShiftFormulas, SamplesAreEvenlySpacedAndEndExactlyAtTheMaximum) {
  const auto samples = lateral_acc_samples(StartPlannerParameters{});
  ASSERT_EQ(samples.size(), 4u);
  EXPECT_DOUBLE_EQ(samples.front(), 0.15);
  EXPECT_NEAR(samples[1], 0.15 + 0.35 / 3, 1e-12);
  EXPECT_NEAR(samples[2], 0.15 + 0.70 / 3, 1e-12);
  EXPECT_DOUBLE_EQ(samples.back(), 0.5);
}

TEST(ShiftFormulas, WorkedNumbersAt60KmH) {
  const StartPlannerParameters p;
  const double expected_time[] = {9.966, 7.799, 6.858, 6.385};
  const double expected_distance[] = {49.66, 30.41, 23.52, 20.39};
  const auto samples = lateral_acc_samples(p);
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const ShiftKinematics k = compute_shift_kinematics(3.5, samples[i], 16.67, p);
    EXPECT_NEAR(k.shift_time, expected_time[i], 0.0006) << "a_lat " << samples[i];
    EXPECT_DOUBLE_EQ(k.longitudinal_acc, 1.0);
    EXPECT_NEAR(k.distance, expected_distance[i], kTableTolerance) << "a_lat " << samples[i];
    EXPECT_NEAR(k.terminal_velocity, k.shift_time, 0.01) << "v_term = a_lon T with a_lon = 1";
  }
}

TEST(ShiftFormulas, SlowRoadLimitsTheLongitudinalAcceleration) {
  const ShiftKinematics k = compute_shift_kinematics(3.5, 0.15, 8.33, StartPlannerParameters{});
  EXPECT_NEAR(k.longitudinal_acc, 0.836, 0.001);
  EXPECT_NEAR(k.distance, 41.52, kTableTolerance + 0.01);  // 0.836 is itself rounded
  EXPECT_NEAR(k.terminal_velocity, 8.33, 0.01);
}

TEST(ShiftFormulas, ShiftTimeIsInfiniteForNonPositiveLimits) {
  EXPECT_TRUE(std::isinf(calc_shift_time_from_jerk(3.5, 0.0, 0.5)));
  EXPECT_TRUE(std::isinf(calc_shift_time_from_jerk(3.5, 0.5, 0.0)));
}

TEST(LateralJerkProfile, ReachesTheShiftLengthAtRestWithinTheAccelerationLimit) {
  for (double L : {0.2, 1.0, 3.5, 8.0}) {
    for (double a : {0.15, 0.3, 0.5}) {
      const auto prof = LateralJerkProfile::from_limits(L, 0.5, a);
      const auto end = prof.at(prof.total_time());
      EXPECT_NEAR(end.position, L, 1e-9) << "L " << L << " a " << a;
      EXPECT_NEAR(end.velocity, 0.0, 1e-9);
      EXPECT_NEAR(end.acceleration, 0.0, 1e-9);
      EXPECT_LE(prof.peak_acceleration(), a + 1e-12);
      // Position never decreases and never overshoots.
      double prev = 0.0;
      for (int i = 0; i <= 200; ++i) {
        const double x = prof.at(prof.total_time() * i / 200).position;
        EXPECT_GE(x, prev - 1e-12);
        EXPECT_LE(x, L + 1e-9);
        prev = x;
      }
    }
  }
}

TEST(ShiftFormulas, CurvatureTermDominatesForShortHighAccelerationShifts) {
  StartPlannerParameters p;
  p.maximum_curvature = 0.01;
  const ShiftKinematics k = compute_shift_kinematics(3.5, 0.5, 16.67, p);
  const double by_curvature = k.shift_time * std::sqrt(k.profile.peak_acceleration() / 0.01);
  EXPECT_NEAR(k.distance, by_curvature, 1e-9);
  EXPECT_GT(k.distance, 0.5 * k.shift_time * k.shift_time);
  EXPECT_NEAR(k.terminal_velocity, std::sqrt(2.0 * k.longitudinal_acc * k.distance), 1e-9);
}

// ---- planner properties ----

struct PathProperties {
  double max_step{0.0};
  double max_yaw_jump{0.0};
  double max_curvature{0.0};
};

PathProperties measure(const PathWithLaneId& path, std::size_t first, std::size_t last) {
  PathProperties m;
  for (std::size_t i = first + 1; i <= last; ++i) {
    const auto& a = path.points[i - 1].pose;
    const auto& b = path.points[i].pose;
    m.max_step = std::max(m.max_step, std::hypot(b.x - a.x, b.y - a.y));
    m.max_yaw_jump = std::max(m.max_yaw_jump, std::abs(normalize_angle(b.yaw - a.yaw)));
  }
  std::vector<Vec2> pts;
  for (std::size_t i = first; i <= last; ++i) pts.push_back(to_vec(path.points[i].pose));
  const Polyline line(pts);
  for (std::size_t i = 1; i + 1 < line.size(); ++i) {
    m.max_curvature = std::max(m.max_curvature, std::abs(line.curvature_at(line.s(i))));
  }
  return m;
}

std::size_t index_of(const PathWithLaneId& path, const Pose2& pose) {
  std::size_t best = 0;
  double best_d = 1e18;
  for (std::size_t i = 0; i < path.points.size(); ++i) {
    const double d = std::hypot(path.points[i].pose.x - pose.x, path.points[i].pose.y - pose.y);
    if (d < best_d) {
      best_d = d;
      best = i;
    }
  }
  return best;
}

TEST(ShiftPullOut, StraightShoulderPathIsContinuousAndEndsOnTheCenterline) {
  const StartPlanner planner(VehicleInfo{}, StartPlannerParameters{});
  const auto req = test::straight_shoulder_request();
  const PlanningResult r = planner.plan(req, StopCondition());
  ASSERT_EQ(r.outcome, PlanningResult::Outcome::kFound) << r.stop_reason;
  const PullOutPath& path = r.path;
  EXPECT_TRUE(path.found);
  EXPECT_EQ(path.planner_type, PlannerType::kShift);
  ASSERT_EQ(path.partial_paths.size(), 1u);
  ASSERT_EQ(path.pairs_terminal_velocity_and_accel.size(), 1u);
  const PathWithLaneId& seg = path.partial_paths[0];
  ASSERT_GE(seg.points.size(), 2u);

  // Starts at the vehicle.
  EXPECT_NEAR(seg.points.front().pose.x, req.ego_pose.x, 1e-9);
  EXPECT_NEAR(seg.points.front().pose.y, req.ego_pose.y, 1e-9);
  // Ends on the centerline (y = 0), at the goal, stopped.
  EXPECT_NEAR(path.end_pose.y, 0.0, 1e-9);
  EXPECT_NEAR(seg.points.back().pose.x, req.goal_pose.x, 1e-9);
  EXPECT_NEAR(seg.points.back().pose.y, 0.0, 1e-9);
  EXPECT_DOUBLE_EQ(seg.points.back().longitudinal_velocity_mps, 0.0);
  EXPECT_NEAR(path.shift_length_m, 3.25, 1e-9);
  EXPECT_EQ(path.turn_signal, TurnSignal::kRight);

  const std::size_t end_idx = index_of(seg, path.end_pose);
  const PathProperties m = measure(seg, 0, seg.points.size() - 1);
  // Points are 1 m apart on the centerline; the shifted path is longer by its lateral motion
  // (and by 1 + k l outside a bend), a few percent here.
  EXPECT_LE(m.max_step, StartPlannerParameters{}.center_line_path_interval * 1.1);
  EXPECT_LE(m.max_yaw_jump, 0.05);  // [rad] between points 1 m apart
  // The lateral offset moves monotonically towards the centerline.
  for (std::size_t i = 1; i < seg.points.size(); ++i) {
    EXPECT_LE(seg.points[i].pose.y, seg.points[i - 1].pose.y + 1e-12) << "point " << i;
  }
  // Curvature within maximum_curvature (the distance formula guarantees it on a straight road;
  // 2 % covers the discrete curvature estimate) and far within the vehicle's limit.
  const PathProperties shift_part = measure(seg, 0, end_idx);
  EXPECT_LE(shift_part.max_curvature, StartPlannerParameters{}.maximum_curvature * 1.02);
  EXPECT_LE(shift_part.max_curvature, 1.0 / VehicleInfo{}.min_turning_radius_m());
  // Velocities: positive until the goal; the pair matches the velocity at the end pose.
  for (std::size_t i = 0; i + 1 < seg.points.size(); ++i) EXPECT_GT(seg.points[i].longitudinal_velocity_mps, 0.0);
  EXPECT_NEAR(seg.points[end_idx].longitudinal_velocity_mps, path.pairs_terminal_velocity_and_accel[0].velocity_mps,
              1e-9);
  // The gentlest candidate wins when nothing is in the way, at the first margin.
  ASSERT_EQ(r.evaluation_table.size(), 1u);
  EXPECT_EQ(r.evaluation_table[0].outcome, AttemptOutcome::kSuccess);
  EXPECT_DOUBLE_EQ(r.evaluation_table[0].margin_m, 2.0);
  const auto k = compute_shift_kinematics(3.25, 0.15, 13.89, StartPlannerParameters{});
  EXPECT_NEAR(path.pairs_terminal_velocity_and_accel[0].velocity_mps, k.terminal_velocity, 1e-9);
  EXPECT_NEAR(path.pairs_terminal_velocity_and_accel[0].accel_mps2, k.longitudinal_acc, 1e-9);
  // The shift section is as long as the kinematics say (within one sample of arc length).
  double len = 0.0;
  for (std::size_t i = 1; i <= end_idx; ++i) {
    len += std::hypot(seg.points[i].pose.x - seg.points[i - 1].pose.x, seg.points[i].pose.y - seg.points[i - 1].pose.y);
  }
  EXPECT_NEAR(len, k.distance, 0.05);
}

TEST(ShiftPullOut, CurvedRoadStaysWithinTheSteeringLimitAndEndsOnTheCenterline) {
  const StartPlanner planner(VehicleInfo{}, StartPlannerParameters{});
  const auto req = test::curved_road_request();
  const PlanningResult r = planner.plan(req, StopCondition());
  ASSERT_EQ(r.outcome, PlanningResult::Outcome::kFound) << r.stop_reason;
  const PathWithLaneId& seg = r.path.partial_paths.at(0);
  const PathProperties m = measure(seg, 0, seg.points.size() - 1);
  EXPECT_LE(m.max_step, 1.1);  // 1 m on the centerline, x (1 + 3.25 / 60) outside the bend
  EXPECT_LE(m.max_curvature, 1.0 / VehicleInfo{}.min_turning_radius_m());
  // The end pose lies on the road centerline: radius 60 around (0, 60) or y = 0 before the arc.
  const Pose2& e = r.path.end_pose;
  const double off = e.x > 0.0 ? std::abs(std::hypot(e.x, e.y - 60.0) - 60.0) : std::abs(e.y);
  EXPECT_LT(off, 0.01);
  // Goal reached: last point on the goal.
  EXPECT_NEAR(seg.points.back().pose.x, req.goal_pose.x, 0.05);
  EXPECT_NEAR(seg.points.back().pose.y, req.goal_pose.y, 0.05);
}

TEST(ShiftPullOut, StartOnTheCenterlineDrivesStraightOn) {
  const StartPlanner planner(VehicleInfo{}, StartPlannerParameters{});
  auto req = test::straight_shoulder_request();
  req.ego_pose = {10.0, 0.0, 0.0};
  const PlanningResult r = planner.plan(req, StopCondition());
  ASSERT_EQ(r.outcome, PlanningResult::Outcome::kFound);
  EXPECT_EQ(r.path.turn_signal, TurnSignal::kNone);
  for (const auto& pt : r.path.partial_paths[0].points) EXPECT_NEAR(pt.pose.y, 0.0, 1e-9);
}

TEST(ShiftPullOut, StartHeadingFarFromTheLaneIsRefused) {
  StartPlannerParameters params;
  params.enable_back = false;  // backed-up candidates are aligned with the lane
  const StartPlanner planner(VehicleInfo{}, params);
  auto req = test::straight_shoulder_request();
  req.ego_pose.yaw = 0.8;
  const PlanningResult r = planner.plan(req, StopCondition());
  EXPECT_EQ(r.outcome, PlanningResult::Outcome::kNoPath);
  ASSERT_FALSE(r.evaluation_table.empty());
  EXPECT_EQ(r.evaluation_table[0].outcome, AttemptOutcome::kStartInvalid);
  EXPECT_NE(r.evaluation_table[0].detail.find("start heading deviates"), std::string::npos);
}

}  // namespace
}  // namespace pullout
