#include "pullout/lane_planners/shift_pull_out.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "path_oracles.hpp"
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
    // d = a_lon T^2 / 2 here, so v_term = sqrt(2 a_lon d) = a_lon T = T (the table's T, 3 decimals).
    EXPECT_NEAR(k.terminal_velocity, expected_time[i], 0.0006) << "a_lat " << samples[i];
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

// The constant-jerk profile in closed form. Jerk +j, 0, -j over t_j, t_a, t_j brings the lateral
// acceleration up to a = j t_j and back to 0, the lateral velocity to its peak a (t_j + t_a); the
// second half mirrors the first. Integrating phase by phase, the first half covers
// a t_j^2 + 3/2 a t_j t_a + 1/2 a t_a^2, so the whole shift covers
//   L = a (t_j + t_a) (2 t_j + t_a)                                               (*)
// and the first phase alone j t_j^3 / 6. The checks below hold the profile to (*) and to these
// phase values; they are exact up to rounding (1e-9 on metres and seconds).
TEST(LateralJerkProfile, MatchesTheClosedFormOfTheConstantJerkShift) {
  for (double L : {0.2, 1.0, 3.5, 8.0}) {
    for (double a : {0.15, 0.3, 0.5}) {
      const double j = 0.5;
      const auto prof = LateralJerkProfile::from_limits(L, j, a);
      const double t_j = prof.t_jerk;
      const double t_a = prof.t_accel;
      const double a_peak = j * t_j;
      EXPECT_NEAR(prof.jerk, j, 1e-12);
      EXPECT_GE(t_a, 0.0);
      EXPECT_LE(a_peak, a + 1e-12) << "L " << L << " a " << a;
      // Either the acceleration limit is reached (t_j = a / j) or there is no constant phase.
      if (t_a > 1e-12) {
        EXPECT_NEAR(t_j, a / j, 1e-12);
      }
      EXPECT_NEAR(a_peak * (t_j + t_a) * (2.0 * t_j + t_a), L, 1e-9) << "(*) L " << L << " a " << a;
      EXPECT_NEAR(prof.total_time(), 4.0 * t_j + 2.0 * t_a, 1e-12);
      // Phase values: end of the first jerk phase, the middle (half way at peak velocity), the end.
      const auto p1 = prof.at(t_j);
      EXPECT_NEAR(p1.position, j * t_j * t_j * t_j / 6.0, 1e-9);
      EXPECT_NEAR(p1.velocity, 0.5 * j * t_j * t_j, 1e-9);
      EXPECT_NEAR(p1.acceleration, a_peak, 1e-9);
      const auto mid = prof.at(0.5 * prof.total_time());
      EXPECT_NEAR(mid.position, 0.5 * L, 1e-9);
      EXPECT_NEAR(mid.velocity, a_peak * (t_j + t_a), 1e-9);
      EXPECT_NEAR(mid.acceleration, 0.0, 1e-9);
      const auto end = prof.at(prof.total_time());
      EXPECT_NEAR(end.position, L, 1e-9) << "L " << L << " a " << a;
      EXPECT_NEAR(end.velocity, 0.0, 1e-9);
      EXPECT_NEAR(end.acceleration, 0.0, 1e-9);
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

// Worked numbers: L = 3.5 m, a_lat = 0.5, j = 0.5, v_road = 16.67, maximum_curvature = 0.01.
//   t_j = a / j = 1 s; (*) gives t_a^2 + 3 t_a + 2 = L / a = 7, so
//   t_a = (-3 + sqrt(9 + 20)) / 2 = 1.19258 s and T = 4 t_j + 2 t_a = 6.38516 s;
//   a_lon = min(16.67 / T, 1) = 1; a_lon T^2 / 2 = 20.385 m; the curvature term (peak curvature
//   a_peak T^2 / d^2 = maximum_curvature) d = T sqrt(0.5 / 0.01) = 45.150 m dominates;
//   v_term = sqrt(2 a_lon d) = 9.5026 m/s. Computed here from the numbers, so 1e-9.
TEST(ShiftFormulas, CurvatureTermDominatesForShortHighAccelerationShifts) {
  StartPlannerParameters p;
  p.maximum_curvature = 0.01;
  ASSERT_DOUBLE_EQ(p.lateral_jerk, 0.5);
  const double t_a = (std::sqrt(29.0) - 3.0) / 2.0;
  const double T = 4.0 + 2.0 * t_a;
  const double d = T * std::sqrt(0.5 / 0.01);
  const ShiftKinematics k = compute_shift_kinematics(3.5, 0.5, 16.67, p);
  EXPECT_NEAR(k.shift_time, T, 1e-9);
  EXPECT_NEAR(T, 6.38516, 1e-5);
  EXPECT_DOUBLE_EQ(k.longitudinal_acc, 1.0);
  EXPECT_NEAR(k.distance, d, 1e-9);
  EXPECT_NEAR(d, 45.150, 1e-3);
  EXPECT_NEAR(k.terminal_velocity, std::sqrt(2.0 * d), 1e-9);
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
  for (std::size_t i = first + 1; i < last; ++i) {
    const double kappa = oracle::menger_curvature(to_vec(path.points[i - 1].pose), to_vec(path.points[i].pose),
                                                  to_vec(path.points[i + 1].pose));
    m.max_curvature = std::max(m.max_curvature, std::abs(kappa));
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
  // Worked numbers for L = 3.25 m, a_lat = 0.15, j = 0.5, v_road = 13.89: t_j = a / j = 0.3 s;
  // the closed form L = a (t_j + t_a) (2 t_j + t_a) gives t_a^2 + 0.9 t_a + 0.18 = 3.25 / 0.15,
  // t_a = (-0.9 + sqrt(0.81 - 4 (0.18 - 21.667))) / 2 = 4.2072 s, T = 4 t_j + 2 t_a = 9.6143 s;
  // a_lon = min(13.89 / T, 1) = 1; d = max(T^2 / 2 = 46.218 m, T sqrt(0.15 / 0.07) = 14.07 m)
  // = 46.218 m; v_term = min(13.89, sqrt(2 d)) = T = 9.6143 m/s. Formulas evaluated here: 1e-9.
  const double t_a = (-0.9 + std::sqrt(0.81 - 4.0 * (0.18 - 3.25 / 0.15))) / 2.0;
  const double T = 1.2 + 2.0 * t_a;
  const double shift_distance = 0.5 * T * T;
  ASSERT_NEAR(T, 9.6143, 1e-4);
  EXPECT_NEAR(path.pairs_terminal_velocity_and_accel[0].velocity_mps, T, 1e-9);
  EXPECT_DOUBLE_EQ(path.pairs_terminal_velocity_and_accel[0].accel_mps2, 1.0);
  // The shift section is as long as the kinematics say (within one sample of arc length).
  PathWithLaneId shift_section = seg;
  shift_section.points.resize(end_idx + 1);
  EXPECT_NEAR(polyline_length(shift_section), shift_distance, 0.05);
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

// A road bending left through the corners of coarse chords, as on Autoware's road_shoulder map
// (bounds drawn every 5 m, each bound with its own vertices), the shoulder on the inside: the
// centerline derived from such bounds turns at its vertices, and 3 m to the inside of a vertex the
// heading from the centerline's interpolated curvature, t (1 - k l), pointed backwards (shoulders
// 10988, 10991, 10994 on that map: yaw 1.54 rad on a path driving at -1.6 rad). Every pose's
// heading must follow the path: within 0.35 rad of the direction to the next point (a 1 m step
// on a path whose curvature is within the vehicle's limit turns far less), never backwards.
TEST(ShiftPullOut, HeadingFollowsThePathInsideTheCornersOfACoarseCenterline) {
  // A straight road, a 90 degree bend to the left of centerline radius 12 m drawn in 3 m chords
  // (each bound with its own vertices), a straight again; the shoulder on the inside.
  const double R = 10.0;
  const auto bend = [R](double radius) { return test::arc_points(0, R, radius, -kPi / 2, 0.0, 3.0); };
  const auto lane = [](std::int64_t id, LaneSubtype subtype, std::vector<Point2> left, std::vector<Point2> right) {
    Lane l;
    l.id = id;
    l.subtype = subtype;
    l.left_bound = std::move(left);
    l.right_bound = std::move(right);
    l.speed_limit_mps = 13.89;
    return l;
  };
  const std::vector<Lane> lanes = {
      test::straight_lane(1, LaneSubtype::kRoad, -40, 0, -1.75, 1.75),
      lane(2, LaneSubtype::kRoad, bend(R - 1.75), bend(R + 1.75)),
      lane(3, LaneSubtype::kRoad, {{R - 1.75, R}, {R - 1.75, R + 80}}, {{R + 1.75, R}, {R + 1.75, R + 80}}),
      test::straight_lane(11, LaneSubtype::kRoadShoulder, -40, 0, 1.75, 6.25),
      lane(12, LaneSubtype::kRoadShoulder, bend(R - 6.25), bend(R - 1.75)),
      lane(13, LaneSubtype::kRoadShoulder, {{R - 6.25, R}, {R - 6.25, R + 80}}, {{R - 1.75, R}, {R - 1.75, R + 80}})};
  StartPlannerParameters params;
  params.enable_back = false;
  params.search_priority = {PlannerType::kShift};
  params.freespace_planner.enable_freespace_planner = false;
  const StartPlanner planner(VehicleInfo{}, params);
  PullOutRequest req;
  req.vehicle_id = "test";
  req.request_id = 1;
  req.lanes = lanes;
  req.ego_pose = {-8.0, 4.0, 0.0};
  req.goal_pose = {R, R + 70.0, kPi / 2};
  const PlanningResult r = planner.plan(req, StopCondition());
  ASSERT_EQ(r.outcome, PlanningResult::Outcome::kFound) << r.stop_reason;
  const PathWithLaneId& seg = r.path.partial_paths.at(0);
  const std::size_t end_idx = index_of(seg, r.path.end_pose);
  ASSERT_GT(end_idx, 10u);
  // The positions do not cusp either: the curvature stays within the vehicle's limit (the bend's
  // inside at the start's offset has a radius of about 6 m; 3.75 m inside the derived centerline's
  // corners, offset point by point, the path reached 0.50 1/m).
  EXPECT_LE(measure(seg, 0, end_idx).max_curvature, 1.0 / VehicleInfo{}.min_turning_radius_m());
  for (std::size_t i = 0; i < end_idx; ++i) {
    const Pose2& a = seg.points[i].pose;
    const Pose2& b = seg.points[i + 1].pose;
    const double chord = std::atan2(b.y - a.y, b.x - a.x);
    EXPECT_LT(std::abs(normalize_angle(a.yaw - chord)), 0.35)
        << "point " << i << " of " << end_idx << ": yaw " << a.yaw << ", towards the next point " << chord;
  }
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
