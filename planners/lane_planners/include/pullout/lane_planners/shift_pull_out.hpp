// Shift pull-out: the road centerline shifted laterally so that it passes through the start pose
// and returns to the centerline with a constant-lateral-jerk profile.
//
// For each lateral acceleration a_lat sampled from minimum_lateral_acc to maximum_lateral_acc
// (lateral_acceleration_sampling_num intervals, gentle first), with lateral jerk j and shift
// length L (the start pose's signed lateral offset from the road centerline):
//   shift time     T = 4 t_j + 2 t_a, t_j = a/j, t_a = (sqrt(a^2 + 4 j^2 L / a) - 3a) / (2j),
//                  or t_j = cbrt(L / 2j), t_a = 0 when t_a would be negative;
//   acceleration   a_lon = clamp(v_road / T, 0, maximum_longitudinal_acc);
//   distance       d = max(a_lon T^2 / 2, T sqrt(a_peak / maximum_curvature),
//                          minimum_shift_pull_out_distance);
//   terminal speed v_term = min(v_road, sqrt(2 a_lon d)).
// The first candidate that stays inside the lanes and clears the static objects by the margin wins.
//
// Differences from Autoware's shift pull-out (reference facts, sections 2.1 and 7), on purpose:
// - The samples are a_min + i (a_max - a_min) / N, i = 0..N, so the last one is exactly a_max
//   (a floating-point accumulation loop gives 0.49999...).
// - The curvature term is the distance at which this jerk-limited profile's peak curvature
//   (a_peak T^2 / d^2) equals maximum_curvature. Autoware's double-arc term sqrt(4L/k - L^2)
//   describes two circular arcs, whose curvature a smooth profile exceeds by up to a factor 2.
// - The lateral offset is the exact piecewise-cubic constant-jerk profile mapped linearly from
//   time to arc length, not a spline through knot points, so it cannot overshoot and no
//   refinement iterations are needed; the path starts exactly at the start pose.
// - The shifted section is offset from the road centerline averaged over +-2.5 m (blended back
//   onto the centerline itself as the shift fades), not from the centerline point by point: a
//   centerline derived from bounds drawn in coarse chords turns 10-14 degrees within a metre at
//   each corner, and 3-4 m inside such a corner the offset cusped (curvature 0.5-1.3 1/m).
//   Autoware offsets a cubic spline through a 5 m centerline.
// - Each shifted pose's heading is the direction the sampled path takes there (the mean of the
//   directions from the pose before and to the pose after), as Autoware's are (the azimuth to the
//   next point), not one from the centerline's curvature (which pointed backwards at such cusps).
// - v_term = sqrt(2 a_lon d) keeps the pair consistent when the curvature term sets d (it equals
//   a_lon T otherwise).
// - The static collision check is never skipped (Autoware skips it for shifts < 0.5 m and ignores
//   zero-speed objects when enable_back is false), and the checked section always contains the
//   start pose even when end_pose + shift_collision_check_distance_from_end lies behind it. Past
//   that section, up to the end pose, the margin is not required but contact still is a collision
//   (Autoware does not check there at all).
#pragma once

#include "pullout/lane_planners/pull_out_planner.hpp"

namespace pullout {

// Constant-jerk lateral motion through distance |L|: jerk +j, 0, -j, -j, 0, +j over phases of
// t_j, t_a, t_j, t_j, t_a, t_j seconds.
struct LateralJerkProfile {
  double jerk{0.0};     // [m/s^3]
  double t_jerk{0.0};   // [s]
  double t_accel{0.0};  // [s]

  static LateralJerkProfile from_limits(double shift_length, double lateral_jerk, double lateral_acc);
  double total_time() const { return 4.0 * t_jerk + 2.0 * t_accel; }
  double peak_acceleration() const { return jerk * t_jerk; }
  // Lateral position, velocity and acceleration at time t in [0, total_time()].
  struct State {
    double position{0.0};
    double velocity{0.0};
    double acceleration{0.0};
  };
  State at(double t) const;
};

// T for a lateral shift of |shift_length| with the given jerk and acceleration limits [s].
// Returns +inf when jerk or acceleration is not positive.
double calc_shift_time_from_jerk(double shift_length, double lateral_jerk, double lateral_acc);

struct ShiftKinematics {
  double lateral_acc{0.0};  // sampled a_lat [m/s^2]
  LateralJerkProfile profile;
  double shift_time{0.0};         // T [s]
  double longitudinal_acc{0.0};   // a_lon [m/s^2]
  double distance{0.0};           // d [m] along the path
  double terminal_velocity{0.0};  // v_term [m/s]
};

ShiftKinematics compute_shift_kinematics(double shift_length, double lateral_acc, double road_velocity,
                                         const LanePlannerParameters& parameters);

// The a_lat samples in the order they are tried.
std::vector<double> lateral_acc_samples(const LanePlannerParameters& parameters);

class ShiftPullOut final : public PullOutPlanner {
 public:
  PlannerType type() const override { return PlannerType::kShift; }
  PlannerCandidates plan(const PlanningContext& context, const Pose2& start, const StopCondition& stop) const override;
};

}  // namespace pullout
