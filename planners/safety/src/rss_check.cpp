#include "pullout/safety/rss_check.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "pullout/geometry/polygon.hpp"

namespace pullout {
namespace {

// Objects slower than this count as standing for the front/rear speeds.
constexpr double kStoppedObjectVelocity = 0.3;  // [m/s]
// Integration step of the stop profile.
constexpr double kStopProfileStep = 0.005;  // [s]
constexpr double kStopProfileMaxSteps = 4096.0;

// Distance travelled after tau seconds from v0 with acceleration a, the speed clamped to
// [v_min, v_max].
double travelled(double v0, double a, double v_min, double v_max, double tau) {
  if (tau <= 0.0) return 0.0;
  const double v_start = std::clamp(v0, v_min, v_max);
  if (a == 0.0) return v_start * tau;
  const double v_limit = a > 0.0 ? v_max : v_min;
  const double t_reach = (v_limit - v_start) / a;  // >= 0
  if (tau <= t_reach) return v_start * tau + 0.5 * a * tau * tau;
  return v_start * t_reach + 0.5 * a * t_reach * t_reach + v_limit * (tau - t_reach);
}

// The rectangle of a vehicle/object body of `length` x `width` around `pose` (centre offset
// `center_x` ahead of the pose), grown forward by `forward` and sideways by `lateral`.
Polygon extended_box(const Pose2& pose, double front, double rear, double half_width, double forward, double lateral) {
  const double f = front + forward;
  const double w = half_width + lateral;
  return {to_global(pose, {f, w}), to_global(pose, {-rear, w}), to_global(pose, {-rear, -w}), to_global(pose, {f, -w})};
}

Pose2 interpolate(const Pose2& a, const Pose2& b, double r) {
  return {a.x + (b.x - a.x) * r, a.y + (b.y - a.y) * r, a.yaw + normalize_angle(b.yaw - a.yaw) * r};
}

// Object half extents along its heading: front, rear, half width.
struct Extents {
  double front;
  double rear;
  double half_width;
};
Extents object_extents(const Object& o) {
  if (o.polygon.empty()) return {0.5 * o.length_m, 0.5 * o.length_m, 0.5 * o.width_m};
  Extents e{0.0, 0.0, 0.0};
  for (const Point2& p : o.polygon) {
    e.front = std::max(e.front, p.x);
    e.rear = std::max(e.rear, -p.x);
    e.half_width = std::max(e.half_width, std::abs(p.y));
  }
  return e;
}

std::string format_reason(const char* what, std::int64_t id, double t) {
  std::ostringstream out;
  out.precision(1);
  out << std::fixed << what << " object " << id << " at t = " << t << " s";
  return out.str();
}

}  // namespace

std::vector<TimedPose> predict_ego_motion(const Polyline& segment, const Pose2& ego, double v0, double max_velocity,
                                          double accel, const EgoPredictedPathParameters& p) {
  std::vector<TimedPose> out;
  if (segment.size() < 2 || p.time_resolution <= 0.0) return out;
  const double s0 = segment.project(to_vec(ego)).s;
  const double v_max = std::max(max_velocity, p.min_velocity);
  const double horizon = std::max(p.time_horizon_for_front_object, p.time_horizon_for_rear_object);
  for (int i = 0;; ++i) {
    const double t = i * p.time_resolution;
    if (t >= horizon - 1e-9) break;
    const double tau = t - p.delay_until_departure;
    double s = 0.0;
    double v = 0.0;
    if (tau >= 0.0) {
      s = travelled(v0, accel, p.min_velocity, v_max, tau);
      v = std::clamp(v0 + accel * tau, p.min_velocity, v_max);
    }
    TimedPose tp;
    tp.t = t;
    tp.velocity = v;
    tp.pose = segment.pose_at(s0 + s);
    const double beyond = s0 + s - segment.length();
    if (beyond > 0.0) {  // pose_at clamps the heading; extend straight along the last heading
      const Pose2 end = segment.pose_at(segment.length());
      tp.pose = {end.x + beyond * std::cos(end.yaw), end.y + beyond * std::sin(end.yaw), end.yaw};
    }
    out.push_back(tp);
  }
  return out;
}

std::vector<TimedPose> sample_object_path(const Object& object, const PredictedPath* path,
                                          const TargetFilteringParameters& p) {
  std::vector<TimedPose> out;
  const double v = std::abs(object.velocity_mps);
  const double dt = p.safety_check_time_resolution;
  if (dt <= 0.0) return out;
  for (int i = 0;; ++i) {
    const double t = i * dt;
    if (t > p.safety_check_time_horizon + 1e-9) break;
    TimedPose tp;
    tp.t = t;
    tp.velocity = v;
    if (path == nullptr || path->poses.empty()) {
      const double d = object.velocity_mps * t;
      tp.pose = {object.pose.x + d * std::cos(object.pose.yaw), object.pose.y + d * std::sin(object.pose.yaw),
                 object.pose.yaw};
    } else {
      const double k = path->time_step_s > 0.0 ? t / path->time_step_s : 0.0;
      const auto last = path->poses.size() - 1;
      if (k > static_cast<double>(last) + 1e-9) break;  // the prediction ends here
      const auto i0 = std::min(static_cast<std::size_t>(k), last);
      const auto i1 = std::min(i0 + 1, last);
      tp.pose = interpolate(path->poses[i0], path->poses[i1], k - static_cast<double>(i0));
    }
    out.push_back(tp);
  }
  return out;
}

double rss_distance(double v_front, double v_rear, const RssParameters& p) {
  const double b_rear = std::abs(p.rear_vehicle_deceleration);
  const double b_front = std::abs(p.front_vehicle_deceleration);
  return v_rear * (p.rear_vehicle_reaction_time + p.rear_vehicle_safety_time_margin) +
         v_rear * v_rear / (2.0 * b_rear) - v_front * v_front / (2.0 * b_front);
}

double rss_longitudinal_offset(double v_front, double v_rear, double v_ego, double v_object, const RssParameters& p) {
  const double d_min = p.longitudinal_velocity_delta_time * std::max(std::abs(v_ego), std::abs(v_object)) +
                       p.longitudinal_distance_min_threshold;
  return std::max(rss_distance(v_front, v_rear, p), d_min);
}

bool polygons_intersect(const Polygon& a, const Polygon& b) {
  if (a.empty() || b.empty()) return false;
  if (!bounding_box(a).overlaps(bounding_box(b))) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const Vec2& a0 = a[i];
    const Vec2& a1 = a[(i + 1) % a.size()];
    for (std::size_t j = 0; j < b.size(); ++j) {
      if (segments_intersect(a0, a1, b[j], b[(j + 1) % b.size()])) return true;
    }
  }
  return point_in_polygon(b, a.front()) || point_in_polygon(a, b.front());
}

RssVerdict check_rss(const std::vector<TimedPose>& ego_path, const Footprint& ego_footprint,
                     const std::vector<Object>& targets, const TargetFilteringParameters& filtering,
                     const SafetyCheckParams& p, double hysteresis) {
  RssVerdict verdict;
  if (ego_path.empty()) return verdict;
  const double dt_ego = ego_path.size() > 1 ? ego_path[1].t - ego_path[0].t : 1.0;
  const double lat = p.rss_params.lateral_distance_max_threshold * hysteresis;
  const double ego_half_width = 0.5 * ego_footprint.width();
  const double ego_center_offset = 0.5 * (ego_footprint.left - ego_footprint.right);

  auto check_path = [&](const Object& object, const PredictedPath* path) -> bool {
    const Extents e = object_extents(object);
    for (const TimedPose& o : sample_object_path(object, path, filtering)) {
      const double k = o.t / dt_ego;
      if (k > static_cast<double>(ego_path.size() - 1) + 1e-9) break;
      const auto i0 = std::min(static_cast<std::size_t>(k), ego_path.size() - 1);
      const auto i1 = std::min(i0 + 1, ego_path.size() - 1);
      const double r = k - static_cast<double>(i0);
      const Pose2 ego = interpolate(ego_path[i0].pose, ego_path[i1].pose, r);
      const double v_ego = ego_path[i0].velocity + (ego_path[i1].velocity - ego_path[i0].velocity) * r;
      if (std::abs(normalize_angle(o.pose.yaw - ego.yaw)) > p.collision_check_yaw_diff_threshold) continue;

      // The ego rectangle is symmetric about its centre line; shift the pose sideways when not.
      const Pose2 ego_mid{ego.x - ego_center_offset * std::sin(ego.yaw), ego.y + ego_center_offset * std::cos(ego.yaw),
                          ego.yaw};
      const Polygon ego_poly = extended_box(ego_mid, ego_footprint.front, ego_footprint.rear, ego_half_width, 0.0, 0.0);
      const Polygon obj_poly = extended_box(o.pose, e.front, e.rear, e.half_width, 0.0, 0.0);
      if (polygons_intersect(ego_poly, obj_poly)) {
        verdict = {false, object.id, o.t, format_reason("collision with", object.id, o.t)};
        return false;
      }
      const bool object_ahead = to_local(ego, to_vec(o.pose)).x() > 0.0;
      const double v_obj = o.velocity < kStoppedObjectVelocity ? 0.0 : o.velocity;
      const double v_front = object_ahead ? v_obj : v_ego;
      const double v_rear = object_ahead ? v_ego : v_obj;
      const double lon = rss_longitudinal_offset(v_front, v_rear, v_ego, v_obj, p.rss_params) * hysteresis;
      const bool unsafe =
          object_ahead
              ? polygons_intersect(
                    extended_box(ego_mid, ego_footprint.front, ego_footprint.rear, ego_half_width, lon, lat), obj_poly)
              : polygons_intersect(extended_box(o.pose, e.front, e.rear, e.half_width, lon, lat), ego_poly);
      if (unsafe) {
        verdict = {false, object.id, o.t,
                   format_reason(object_ahead ? "RSS distance to front" : "RSS distance to rear", object.id, o.t)};
        return false;
      }
    }
    return true;
  };

  for (const Object& object : targets) {
    if (object.predicted_paths.empty()) {
      if (!check_path(object, nullptr)) return verdict;
      continue;
    }
    if (filtering.use_all_predicted_path) {
      for (const PredictedPath& path : object.predicted_paths) {
        if (!check_path(object, &path)) return verdict;
      }
    } else {
      const auto best =
          std::max_element(object.predicted_paths.begin(), object.predicted_paths.end(),
                           [](const PredictedPath& a, const PredictedPath& b) { return a.confidence < b.confidence; });
      if (!check_path(object, &*best)) return verdict;
    }
  }
  return verdict;
}

StopProfile::StopProfile(double v0, double max_deceleration, double max_jerk) {
  double v = std::max(v0, 0.0);
  double s = 0.0;
  double a = 0.0;
  s_.push_back(0.0);
  v_.push_back(v);
  // The stop lasts at most v / max_deceleration + max_deceleration / max_jerk; the step grows
  // with it so that a stop from any speed costs at most about kStopProfileMaxSteps samples.
  const double duration = v / max_deceleration + max_deceleration / max_jerk;
  if (!(max_deceleration > 0.0) || !(max_jerk > 0.0) || !std::isfinite(duration)) {
    // Never stops (the callers validate speeds and parameters; this keeps the work finite).
    distance_ = std::numeric_limits<double>::infinity();
    return;
  }
  const double step = std::max(kStopProfileStep, duration / kStopProfileMaxSteps);
  s_.reserve(static_cast<std::size_t>(duration / step) + 2);
  v_.reserve(s_.capacity());
  while (v > 0.0) {
    const double a_next = std::min(a + max_jerk * step, max_deceleration);
    const double a_mid = 0.5 * (a + a_next);
    double dt = step;
    if (v - a_mid * dt <= 0.0) dt = v / a_mid;  // the last step ends exactly at v = 0
    s += v * dt - 0.5 * a_mid * dt * dt;
    v = std::max(v - a_mid * dt, 0.0);
    a = a_next;
    s_.push_back(s);
    v_.push_back(v);
  }
  distance_ = s;
}

double StopProfile::velocity_at(double s) const {
  if (s <= 0.0 || s_.size() < 2) return v_.front();
  if (s >= distance_) return 0.0;
  const auto it = std::upper_bound(s_.begin(), s_.end(), s);
  const auto i = static_cast<std::size_t>(it - s_.begin());
  const double r = (s - s_[i - 1]) / std::max(s_[i] - s_[i - 1], 1e-12);
  return v_[i - 1] + (v_[i] - v_[i - 1]) * r;
}

std::optional<std::int64_t> moving_object_around(const Pose2& ego, const std::vector<Object>& objects,
                                                 const SurroundMovingObstacleCheckParameters& p) {
  for (const Object& o : objects) {
    if (!p.object_types_to_check.includes(o.object_class)) continue;
    if (std::abs(o.velocity_mps) <= p.th_moving_obstacle_velocity) continue;
    if ((to_vec(o.pose) - to_vec(ego)).norm() < p.search_radius) return o.id;
  }
  return std::nullopt;
}

}  // namespace pullout
