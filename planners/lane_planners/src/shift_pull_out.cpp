#include "pullout/lane_planners/shift_pull_out.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "pullout/collision/footprint.hpp"
#include "pullout/geometry/angle.hpp"

namespace pullout {

namespace {

constexpr double kMinShiftLength = 0.01;        // [m] below this the start is on the centerline
constexpr double kMaxStartYawDeviation = 0.35;  // [rad] (20 deg) between start heading and lane

// Arc length where the shift may end: the first centerline position at or after s0 whose
// curvature is below the threshold, or the least curved one if none is (so that the shift does
// not end in the middle of a bend).
double push_end_to_low_curvature(const Polyline& center, double s0, double threshold) {
  if (std::abs(center.curvature_at(s0)) < threshold) return s0;
  double best_s = s0;
  double best_k = std::abs(center.curvature_at(s0));
  for (std::size_t i = 0; i < center.size(); ++i) {
    if (center.s(i) <= s0) continue;
    const double k = std::abs(center.curvature_at(center.s(i)));
    if (k < threshold) return center.s(i);
    if (k < best_k) {
      best_k = k;
      best_s = center.s(i);
    }
  }
  return best_s;
}

// Lateral offset l of the shifted path at centerline arc length s, and the share w (1 at the
// start, 0 at the shift end) of the start residual still applied.
struct Offset {
  double l{0.0};
  double w{0.0};
  Vec2 residual{Vec2::Zero()};
};

class ShiftShape {
 public:
  ShiftShape(const LateralJerkProfile& profile, double shift_length, double s_begin, double length)
      : profile_(profile),
        total_(profile.at(profile.total_time()).position),
        shift_length_(shift_length),
        s_begin_(s_begin),
        length_(length) {}

  Offset at(double s) const {
    if (s >= s_begin_ + length_) return {};
    const double u = std::clamp((s - s_begin_) / length_, 0.0, 1.0);
    const double time = u * profile_.total_time();
    const auto st = profile_.at(time);
    const double p = st.position / total_;
    return {shift_length_ * (1.0 - p), 1.0 - p, residual_};
  }

  double end() const { return s_begin_ + length_; }

  // Where the start lies in the fan outside a corner of the centerline polyline, the point at
  // lateral offset l from its projection misses it (by up to l (1 - cos) of the corner's angle):
  // that residual is carried by the same profile, whole at the start and gone at the shift end,
  // so that the path starts exactly at the vehicle.
  void set_residual(const Vec2& r) { residual_ = r; }

 private:
  LateralJerkProfile profile_;
  double total_;
  double shift_length_;
  double s_begin_;
  double length_;
  Vec2 residual_{Vec2::Zero()};
};

// [m] Half the length over which the reference of the shifted section is averaged, and the
// spacing of its table (the derived centerline's own sampling).
constexpr double kReferenceHalfWindow = 2.5;
constexpr double kReferenceStep = 0.5;

// What the shifted section is offset from: the road's centerline averaged over
// +-kReferenceHalfWindow, tabulated along the centerline's arc length. Offsetting the centerline
// itself point by point cusps 3-4 m inside its corners: derived from bounds drawn in coarse
// chords it turns by 10-14 degrees within a metre at each corner (Autoware's road_shoulder map:
// peak curvature 0.83 1/m with the start's offset held over the first 25 m beside shoulder 10988,
// 0.28 averaged; Autoware offsets a cubic spline through a 5 m centerline). The shifted positions
// return onto the centerline itself as the shift fades (raw - averaged, weighted by 1 - w), so the
// path still ends on it exactly. On a straight road the average is the centerline.
class ShiftReference {
 public:
  ShiftReference(const Polyline& center, double s0, double s1) : center_(center), s0_(s0) {
    // The centerline every kReferenceStep from s0 - window to s1 + window, and a running sum over
    // it: each entry the mean of the 2 half + 1 samples around it.
    const auto half = static_cast<std::size_t>(std::lround(kReferenceHalfWindow / kReferenceStep));
    const auto entries =
        std::max<std::size_t>(2, static_cast<std::size_t>(std::ceil(std::max(0.0, s1 - s0) / kReferenceStep)) + 1);
    std::vector<Vec2> prefix{Vec2::Zero()};
    prefix.reserve(entries + 2 * half + 1);
    for (std::size_t k = 0; k < entries + 2 * half; ++k) {
      const double s = s0 + (static_cast<double>(k) - static_cast<double>(half)) * kReferenceStep;
      prefix.push_back(prefix.back() + center.point_at(s));
    }
    std::vector<Vec2> points;
    points.reserve(entries);
    for (std::size_t k = 0; k < entries; ++k) {
      points.push_back((prefix[k + 2 * half + 1] - prefix[k]) / static_cast<double>(2 * half + 1));
    }
    averaged_ = Polyline(points);
    // Arc length on the averaged line at each table entry (as the Polyline sums it; entries are
    // kReferenceStep apart along the centerline, never coincident).
    along_.reserve(points.size());
    along_.push_back(0.0);
    for (std::size_t k = 1; k < points.size(); ++k)
      along_.push_back(along_.back() + (points[k] - points[k - 1]).norm());
  }

  const Polyline& center() const { return center_; }

  // The averaged point at centerline arc length s and the left normal of its heading there.
  std::pair<Vec2, Vec2> at(double s) const {
    const double u = std::clamp((s - s0_) / kReferenceStep, 0.0, static_cast<double>(along_.size() - 1));
    const std::size_t k = std::min(static_cast<std::size_t>(u), along_.size() - 2);
    const double t = u - static_cast<double>(k);
    const Pose2 q = averaged_.pose_at(along_[k] + t * (along_[k + 1] - along_[k]));
    return {to_vec(q), left_normal(heading(q.yaw))};
  }

 private:
  const Polyline& center_;
  double s0_;
  Polyline averaged_;
  std::vector<double> along_;
};

Vec2 shifted_position(const ShiftReference& ref, double s, const Offset& o) {
  Vec2 raw = ref.center().point_at(s);
  if (o.l == 0.0 && o.w == 0.0) return raw;  // beyond the shift: the centerline
  const auto [base, normal] = ref.at(s);
  return base + normal * o.l + o.residual * o.w + (raw - base) * (1.0 - o.w);
}

// Path length of the shifted section over centerline length `length` from s_begin.
double shifted_length(const ShiftReference& ref, const ShiftShape& shape, double s_begin, double length) {
  constexpr int kSteps = 64;
  double total = 0.0;
  Vec2 prev = shifted_position(ref, s_begin, shape.at(s_begin));
  for (int i = 1; i <= kSteps; ++i) {
    const double s = s_begin + length * i / kSteps;
    const Vec2 p = shifted_position(ref, s, shape.at(s));
    total += (p - prev).norm();
    prev = p;
  }
  return total;
}

struct Candidate {
  std::vector<Pose2> poses;
  std::vector<double> s;  // centerline arc length of each pose
  std::size_t shift_end_index{0};
};

// Arc lengths from s_start to the path end every center_line_path_interval, with the shift end
// included exactly; poses for those up to `s_poses_until` only (the checks need no more; the
// winner gets the rest in extend_poses).
Candidate sample_poses(const PlanningContext& ctx, const ShiftReference& ref, const ShiftShape& shape, double s_start,
                       const RoadEnd& end, double s_poses_until) {
  const double step = ctx.parameters.center_line_path_interval;
  Candidate c;
  for (double s = s_start; s < end.s - 1e-6; s += step) c.s.push_back(s);
  c.s.push_back(end.s);
  if (shape.end() > s_start && shape.end() < end.s) {
    const auto it = std::lower_bound(c.s.begin(), c.s.end(), shape.end());
    if (std::abs(*it - shape.end()) > 1e-6 && (it == c.s.begin() || std::abs(*(it - 1) - shape.end()) > 1e-6)) {
      c.s.insert(it, shape.end());
    }
  }
  for (std::size_t i = 0; i < c.s.size(); ++i) {
    if (c.s[i] <= shape.end() + 1e-9) c.shift_end_index = i;
  }
  c.poses.reserve(c.s.size());
  const Polyline& center = ctx.road.centerline;
  for (std::size_t i = 0; i < c.s.size() && (i == 0 || c.s[i] <= s_poses_until + 1e-9); ++i) {
    const Vec2 p = shifted_position(ref, c.s[i], shape.at(c.s[i]));
    c.poses.push_back({p.x(), p.y(), center.yaw_at(c.s[i])});
  }
  // Headings over the shift: the direction the sampled path itself takes at each pose (the mean
  // of the directions from the pose before and to the pose after; to the next one at the start),
  // not t (1 - k l) + n l' from the centerline's curvature. The centerline derived from a bend
  // drawn in coarse chords turns by 10-14 degrees within a metre at each chord's corner, and 3-4 m
  // to the inside of such a corner k l > 1: offset point by point, the curve cusped there within
  // centimetres (ShiftReference now averages it away) and that formula turned the heading
  // backwards (on Autoware's road_shoulder map, shoulders 10988, 10991, 10994: yaw 1.54 rad on a
  // path driving at -1.6 rad, and the lane check turned the footprint with it). On the centerline
  // (from the shift end on) its own heading stays.
  const std::size_t last_shifted = std::min(c.shift_end_index, c.poses.size() - 1);
  std::vector<double> yaws(last_shifted);
  for (std::size_t i = 0; i < last_shifted; ++i) {
    const Vec2 ahead = (to_vec(c.poses[i + 1]) - to_vec(c.poses[i])).normalized();
    const Vec2 behind = i == 0 ? ahead : (to_vec(c.poses[i]) - to_vec(c.poses[i - 1])).normalized();
    const Vec2 d = ahead + behind;
    yaws[i] = d.squaredNorm() > 1e-12 ? std::atan2(d.y(), d.x()) : std::atan2(ahead.y(), ahead.x());
  }
  for (std::size_t i = 0; i < last_shifted; ++i) c.poses[i].yaw = yaws[i];
  return c;
}

// Beyond the shift the path is the centerline itself.
void extend_poses(const PlanningContext& ctx, Candidate& c) {
  for (std::size_t i = c.poses.size(); i < c.s.size(); ++i) c.poses.push_back(ctx.road.centerline.pose_at(c.s[i]));
}

// Velocities: capped at v_term up to the shift end, the lane speed limit after it, 0 at the goal.
PathWithLaneId to_path(const PlanningContext& ctx, const Candidate& c, const RoadEnd& end, double v_term) {
  PathWithLaneId path;
  path.points.resize(c.poses.size());
  for (std::size_t i = 0; i < c.poses.size(); ++i) {
    PathPoint& pt = path.points[i];
    pt.pose = c.poses[i];
    const double limit = speed_limit_at(ctx, c.s[i]);
    pt.longitudinal_velocity_mps = i <= c.shift_end_index ? std::min(limit, v_term) : limit;
    pt.lane_ids = lane_ids_at(ctx, to_vec(pt.pose), road_lane_id_at(ctx, c.s[i]));
  }
  if (end.is_goal) path.points.back().longitudinal_velocity_mps = 0.0;
  return path;
}

}  // namespace

LateralJerkProfile LateralJerkProfile::from_limits(double shift_length, double lateral_jerk, double lateral_acc) {
  const double L = std::abs(shift_length);
  const double j = lateral_jerk;
  const double a = lateral_acc;
  LateralJerkProfile p{j, a / j, (std::sqrt(a * a + 4.0 * j * j * L / a) - 3.0 * a) / (2.0 * j)};
  if (p.t_accel < 0.0) {
    // The acceleration limit is never reached: a pure jerk profile (peak j t_j < a).
    p.t_jerk = std::cbrt(L / (2.0 * j));
    p.t_accel = 0.0;
  }
  return p;
}

LateralJerkProfile::State LateralJerkProfile::at(double t) const {
  const double durations[6] = {t_jerk, t_accel, t_jerk, t_jerk, t_accel, t_jerk};
  const double jerks[6] = {jerk, 0.0, -jerk, -jerk, 0.0, jerk};
  State s;
  double remaining = std::clamp(t, 0.0, total_time());
  for (int k = 0; k < 6 && remaining > 0.0; ++k) {
    const double dt = std::min(remaining, durations[k]);
    const double jk = jerks[k];
    s.position += s.velocity * dt + s.acceleration * dt * dt / 2.0 + jk * dt * dt * dt / 6.0;
    s.velocity += s.acceleration * dt + jk * dt * dt / 2.0;
    s.acceleration += jk * dt;
    remaining -= dt;
  }
  return s;
}

double calc_shift_time_from_jerk(double shift_length, double lateral_jerk, double lateral_acc) {
  if (lateral_jerk <= 0.0 || lateral_acc <= 0.0) return std::numeric_limits<double>::infinity();
  return LateralJerkProfile::from_limits(shift_length, lateral_jerk, lateral_acc).total_time();
}

ShiftKinematics compute_shift_kinematics(double shift_length, double lateral_acc, double road_velocity,
                                         const LanePlannerParameters& p) {
  ShiftKinematics k;
  k.lateral_acc = lateral_acc;
  k.profile = LateralJerkProfile::from_limits(shift_length, p.lateral_jerk, lateral_acc);
  k.shift_time = k.profile.total_time();
  const double T = k.shift_time;
  k.longitudinal_acc = std::clamp(road_velocity / T, 0.0, p.maximum_longitudinal_acc);
  const double by_acceleration = 0.5 * k.longitudinal_acc * T * T;
  const double by_curvature = T * std::sqrt(k.profile.peak_acceleration() / p.maximum_curvature);
  k.distance = std::max({by_acceleration, by_curvature, p.minimum_shift_pull_out_distance});
  k.terminal_velocity = std::min(road_velocity, std::sqrt(2.0 * k.longitudinal_acc * k.distance));
  return k;
}

std::vector<double> lateral_acc_samples(const LanePlannerParameters& p) {
  std::vector<double> out;
  const int n = std::max(p.lateral_acceleration_sampling_num, 1);
  if (p.maximum_lateral_acc - p.minimum_lateral_acc < 1e-9) return {p.minimum_lateral_acc};
  for (int i = 0; i <= n; ++i) {
    out.push_back(p.minimum_lateral_acc + (p.maximum_lateral_acc - p.minimum_lateral_acc) * i / n);
  }
  return out;
}

PlannerCandidates ShiftPullOut::plan(const PlanningContext& ctx, const Pose2& start, const StopCondition& stop) const {
  const auto& params = ctx.parameters;
  const Polyline& center = ctx.road.centerline;
  PlannerCandidates out;
  if (center.size() < 2) {
    out.failure = Failure{AttemptOutcome::kNoGeometry, "no road centerline"};
    return out;
  }
  const auto proj = center.project(to_vec(start));
  const double s_start = proj.s;
  const double shift_length = proj.lateral;
  if (s_start < 0.0 || s_start >= center.length()) {
    out.failure = Failure{AttemptOutcome::kStartInvalid, "start pose is not alongside the road lanes"};
    return out;
  }
  const double yaw_dev = normalize_angle(start.yaw - center.yaw_at(s_start));
  if (std::abs(yaw_dev) > kMaxStartYawDeviation) {
    out.failure = Failure{AttemptOutcome::kStartInvalid,
                          "start heading deviates " + format_fixed(yaw_dev * kRadToDeg, 1) +
                              " deg from the road (limit " + format_fixed(kMaxStartYawDeviation * kRadToDeg, 0) + ")"};
    return out;
  }
  const RoadEnd end = find_path_end(ctx, s_start);
  const ShiftReference reference(center, s_start, end.s);
  const double v_road = speed_limit_at(ctx, s_start);

  std::vector<ShiftKinematics> kinematics;
  if (std::abs(shift_length) < kMinShiftLength) {
    // Already on the centerline: drive straight on, accelerating towards the speed limit.
    ShiftKinematics straight;
    straight.longitudinal_acc = params.maximum_longitudinal_acc;
    straight.terminal_velocity = v_road;
    kinematics.push_back(straight);
  } else {
    for (double a_lat : lateral_acc_samples(params)) {
      kinematics.push_back(compute_shift_kinematics(shift_length, a_lat, v_road, params));
    }
  }

  // Lane departure is checked unless disabled, or (override) unless the vehicle already stands
  // partly outside the lanes.
  bool check_lanes = params.check_shift_path_lane_departure;
  const Footprint departure_footprint = vehicle_footprint(ctx.vehicle, params.lane_departure_check_expansion_margin);
  if (check_lanes && params.allow_check_shift_path_lane_departure_override) {
    check_lanes = !first_lane_departure(ctx, {start}, 0, 0, departure_footprint).has_value();
  }

  for (const ShiftKinematics& k : kinematics) {
    out.stopped = stop.check();
    if (out.stopped != StopReason::kNone) break;
    PathCandidate candidate;
    double length = k.distance;
    std::optional<ShiftShape> shape;
    if (k.distance > 0.0) {
      // Centerline length whose shifted section is k.distance long (differs on curves).
      for (int iter = 0; iter < 2; ++iter) {
        const ShiftShape trial(k.profile, shift_length, s_start, length);
        length *= k.distance / shifted_length(reference, trial, s_start, length);
      }
      const double s_end = push_end_to_low_curvature(center, s_start + length, params.end_pose_curvature_threshold);
      if (s_end > end.s - 1e-6) {
        candidate.rejection = Failure{AttemptOutcome::kNoGeometry, end.is_goal ? "goal too close for the shift"
                                                                               : "road lanes too short for the shift"};
        out.candidates.push_back(std::move(candidate));
        continue;
      }
      shape.emplace(k.profile, shift_length, s_start, s_end - s_start);
      shape->set_residual(to_vec(start) - shifted_position(reference, s_start, shape->at(s_start)));
    } else {
      shape.emplace(k.profile, 0.0, s_start, 0.0);
    }
    // Collision section: from the start to end_pose + shift_collision_check_distance_from_end.
    const double s_check_end = shape->end() + params.shift_collision_check_distance_from_end;
    auto c = std::make_shared<Candidate>(
        sample_poses(ctx, reference, *shape, s_start, end, std::max(shape->end(), s_check_end)));
    std::size_t section_last = 0;
    while (section_last + 1 < c->s.size() && c->s[section_last + 1] <= s_check_end) ++section_last;
    check_candidate(ctx, c->poses,
                    {check_lanes, departure_footprint, c->shift_end_index, section_last,
                     std::max(section_last, c->shift_end_index)},
                    candidate);
    candidate.build = [&ctx, c, end, k, shift_length]() {
      extend_poses(ctx, *c);
      PullOutPath path;
      path.start_pose = c->poses.front();
      path.end_pose = c->poses[c->shift_end_index];
      path.shift_length_m = std::abs(shift_length) < kMinShiftLength ? 0.0 : shift_length;
      path.partial_paths.push_back(to_path(ctx, *c, end, k.terminal_velocity));
      path.pairs_terminal_velocity_and_accel.push_back({k.terminal_velocity, k.longitudinal_acc});
      return path;
    };
    out.candidates.push_back(std::move(candidate));
  }
  return out;
}

}  // namespace pullout
