#include "pullout/pipeline/published_path.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "pullout/collision/object_checker.hpp"
#include "pullout/geometry/polyline.hpp"
#include "pullout/lane_planners/pull_out_planner.hpp"

namespace pullout {

namespace {

constexpr double kTouchingDistance = 1e-6;  // [m] clearance below this is contact
constexpr double kStopResolution = 0.01;    // [m] precision of the stop pose between two points

double distance(const Pose2& a, const Pose2& b) { return std::hypot(b.x - a.x, b.y - a.y); }

Pose2 interpolate(const Pose2& a, const Pose2& b, double t) {
  return {a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t, normalize_angle(a.yaw + normalize_angle(b.yaw - a.yaw) * t)};
}

// The highest speed <= `limit` from which the stop needs at most `room` metres.
double stoppable_speed(double room, double limit, const PublishedPathLimits& l) {
  if (room <= 0.0) return 0.0;
  if (jerk_limited_stop_distance(limit, l.max_deceleration_mps2, l.max_jerk_mps3) <= room) return limit;
  double lo = 0.0;
  double hi = limit;
  for (int i = 0; i < 60 && hi - lo > 1e-9; ++i) {
    const double mid = 0.5 * (lo + hi);
    (jerk_limited_stop_distance(mid, l.max_deceleration_mps2, l.max_jerk_mps3) <= room ? lo : hi) = mid;
  }
  return lo;
}

// Where the path ends when nothing is in the way.
std::string clear_note(const PathPoint& last, double beyond) {
  std::string note = "no object on the published path; it ends " + format_fixed(beyond, 1) + " m beyond the end pose";
  if (std::abs(last.longitudinal_velocity_mps) < 1e-9) return note + ", stopped";
  return note + " at " + format_fixed(std::abs(last.longitudinal_velocity_mps), 1) + " m/s (end of the road lanes or " +
         "forward_path_length)";
}

}  // namespace

double jerk_limited_stop_distance(double speed, double max_deceleration, double max_jerk) {
  const double v = std::abs(speed);
  const double a = max_deceleration;
  const double j = max_jerk;
  if (v <= 0.0) return 0.0;
  // The deceleration ramps up at j and down at j; it reaches a only if v >= a^2 / j.
  if (v >= a * a / j) return v * v / (2.0 * a) + v * a / (2.0 * j);
  return v * std::sqrt(v / j);  // peak deceleration sqrt(v j), ramps of sqrt(v / j) each
}

PublishedPathEnd finish_published_path(PullOutPath& path, const ObjectChecker& objects,
                                       const PublishedPathLimits& limits) {
  PublishedPathEnd out;
  auto& parts = path.partial_paths;
  if (parts.empty() || parts.back().points.empty()) return out;
  const std::size_t last = parts.size() - 1;

  // The end pose: the point of the last partial path nearest to path.end_pose.
  std::size_t end_index = 0;
  {
    double best = std::numeric_limits<double>::infinity();
    const auto& pts = parts[last].points;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const double d = distance(pts[i].pose, path.end_pose);
      if (d < best) {
        best = d;
        end_index = i;
      }
    }
  }
  const double end_clearance = objects.clearance(parts[last].points[end_index].pose, limits.margin_m).distance;
  const double beyond_margin = std::max(kTouchingDistance, std::min(limits.margin_m, end_clearance));
  const auto required = [&](std::size_t k, std::size_t i) {
    return k == last && i > end_index ? beyond_margin : kTouchingDistance;
  };

  // Arc length of every point along the whole path (partial paths join point to point).
  std::vector<std::vector<double>> s(parts.size());
  double total = 0.0;
  for (std::size_t k = 0; k < parts.size(); ++k) {
    const auto& pts = parts[k].points;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      if (i > 0) total += distance(pts[i - 1].pose, pts[i].pose);
      s[k].push_back(total);
    }
  }
  const double s_end = s[last][end_index];

  // The first point that fails its check.
  std::size_t cut_k = parts.size();
  std::size_t cut_i = 0;
  ObjectChecker::Clearance hit;
  for (std::size_t k = 0; k < parts.size() && cut_k == parts.size(); ++k) {
    const auto& pts = parts[k].points;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const double need = required(k, i);
      const auto c = objects.clearance(pts[i].pose, need);
      if (c.distance < need) {
        cut_k = k;
        cut_i = i;
        hit = c;
        break;
      }
    }
  }
  if (cut_k == parts.size()) {
    out.beyond_end_pose_m = s[last].back() - s_end;
    out.note = clear_note(parts[last].points.back(), out.beyond_end_pose_m);
    return out;
  }

  // The stop: the farthest pose before the failing point that still passes.
  PathWithLaneId& seg = parts[cut_k];
  const double planned_end_speed =
      cut_k == last && end_index < cut_i ? std::abs(seg.points[end_index].longitudinal_velocity_mps) : 0.0;
  double s_stop = s[cut_k][cut_i];
  if (cut_i == 0) {
    seg.points.resize(1);  // only the start pose itself (it is in contact: a planner defect)
  } else {
    const Pose2 a = seg.points[cut_i - 1].pose;
    const Pose2 b = seg.points[cut_i].pose;
    const double need = required(cut_k, cut_i);
    const double len = distance(a, b);
    double lo = 0.0;
    double hi = 1.0;
    while ((hi - lo) * len > kStopResolution) {
      const double mid = 0.5 * (lo + hi);
      (objects.clearance(interpolate(a, b, mid), need).distance >= need ? lo : hi) = mid;
    }
    PathPoint stop = seg.points[cut_i - 1];
    seg.points.resize(cut_i);
    if (lo * len > kStopResolution) {
      stop.pose = interpolate(a, b, lo);
      seg.points.push_back(std::move(stop));
    }
    s_stop = s[cut_k][cut_i - 1] + lo * len;
  }
  if (seg.points.size() < 2) seg.points.push_back(seg.points.back());
  parts.resize(cut_k + 1);
  if (path.pairs_terminal_velocity_and_accel.size() > cut_k + 1)
    path.pairs_terminal_velocity_and_accel.resize(cut_k + 1);

  // The ramp down to 0 at the stop.
  std::vector<double> room(seg.points.size(), 0.0);
  for (std::size_t i = seg.points.size() - 1; i-- > 0;) {
    room[i] = room[i + 1] + distance(seg.points[i].pose, seg.points[i + 1].pose);
  }
  for (std::size_t i = 0; i < seg.points.size(); ++i) {
    double& v = seg.points[i].longitudinal_velocity_mps;
    v = std::copysign(stoppable_speed(room[i], std::abs(v), limits), v);
  }
  seg.points.back().longitudinal_velocity_mps = 0.0;

  out.stops_before_object = true;
  out.object_id = hit.obstacle_id;
  out.clearance_m = objects.clearance(seg.points.back().pose).distance;
  out.beyond_end_pose_m = cut_k == last ? s_stop - s_end : -(s_end - s_stop);
  std::string note = "stops " + format_fixed(out.clearance_m, 2) + " m before object " + std::to_string(out.object_id) +
                     ", " + format_fixed(std::abs(out.beyond_end_pose_m), 1) + " m " +
                     (out.beyond_end_pose_m >= 0.0 ? "beyond" : "before") + " the end pose";
  if (out.beyond_end_pose_m < 0.0) note += " (closer than the planner's own checks allow)";
  if (cut_k == last && end_index < seg.points.size()) {
    const double end_speed = std::abs(seg.points[end_index].longitudinal_velocity_mps);
    if (end_speed < planned_end_speed - 1e-6) {
      out.stop_within_limits = false;
      auto& pairs = path.pairs_terminal_velocity_and_accel;
      if (cut_k < pairs.size() && std::abs(pairs[cut_k].velocity_mps) > end_speed) {
        pairs[cut_k].velocity_mps = std::copysign(end_speed, pairs[cut_k].velocity_mps);
      }
      note +=
          "; too close to stop from " + format_fixed(planned_end_speed, 1) + " m/s within " +
          format_fixed(limits.max_deceleration_mps2, 1) + " m/s^2 and " + format_fixed(limits.max_jerk_mps3, 1) +
          " m/s^3 (needs " +
          format_fixed(
              jerk_limited_stop_distance(planned_end_speed, limits.max_deceleration_mps2, limits.max_jerk_mps3), 1) +
          " m): the speed at the end pose is lowered to " + format_fixed(end_speed, 1) +
          " m/s and comes down to 0 at the stop";
    }
  }
  out.note = std::move(note);
  return out;
}

}  // namespace pullout
