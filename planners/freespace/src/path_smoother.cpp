#include "pullout/freespace/path_smoother.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include <Eigen/Dense>

#include "pullout/geometry/angle.hpp"

namespace pullout {

namespace {

constexpr double kCurvatureTolerance = 1e-6;  // relative
constexpr double kSafety = 0.999;             // of the step the sweep argument allows (float rounding)
constexpr int kCloseRounds = 8;               // Gauss-Newton steps of the end correction
constexpr double kClosed = 1e-9;              // [m], [rad] end error of a closed segment
constexpr double kJacobianStep = 1e-6;        // of the correction unknowns
constexpr double kMaxStretch = 0.05;          // of the arc lengths

// [first, last] index ranges of the direction segments: a segment ends where the motion after a
// waypoint goes the other way (as split_at_cusps cuts the partial paths).
std::vector<std::pair<std::size_t, std::size_t>> direction_segments(const std::vector<Waypoint>& w) {
  std::vector<std::pair<std::size_t, std::size_t>> out;
  std::size_t first = 0;
  for (std::size_t i = 1; i < w.size(); ++i) {
    if (i + 1 < w.size() && w[i + 1].direction == w[i].direction) continue;
    out.emplace_back(first, i);
    first = i;
  }
  return out;
}

// One step of a direction segment: an arc of `length` [m] (> 0, driven in the segment's
// direction) and signed curvature [1/m] of the path (left positive, whatever the direction).
struct Interval {
  double length;
  double curvature;
};

// The motion direction's heading of a pose: the vehicle's heading, reversed when reversing.
double travel_heading(const Pose2& pose, int direction) {
  return direction < 0 ? normalize_angle(pose.yaw + kPi) : pose.yaw;
}

// The arcs between consecutive waypoints of [first, last] (each the single arc that leaves the
// first pose's travel heading and turns by the heading difference, length from the chord). False
// when two waypoints coincide.
bool intervals_of(const std::vector<Waypoint>& w, std::size_t first, std::size_t last, int direction,
                  std::vector<Interval>& out) {
  out.clear();
  for (std::size_t i = first; i < last; ++i) {
    const Pose2& a = w[i].pose;
    const Pose2& b = w[i + 1].pose;
    const double chord = std::hypot(b.x - a.x, b.y - a.y);
    if (chord < 1e-9) return false;
    const double turn = normalize_angle(travel_heading(b, direction) - travel_heading(a, direction));
    const double half = 0.5 * turn;
    const double length = std::abs(half) < 1e-9 ? chord : chord * half / std::sin(half);
    out.push_back({length, turn / length});
  }
  return true;
}

// The poses along `intervals` from `start` (exact arcs).
void integrate(const Pose2& start, int direction, const std::vector<Interval>& intervals, std::vector<Pose2>& out) {
  out.assign(1, start);
  double x = start.x;
  double y = start.y;
  double heading = travel_heading(start, direction);
  for (const Interval& iv : intervals) {
    const double turn = iv.curvature * iv.length;
    if (std::abs(turn) < 1e-9) {
      x += iv.length * std::cos(heading + 0.5 * turn);
      y += iv.length * std::sin(heading + 0.5 * turn);
    } else {
      x += (std::sin(heading + turn) - std::sin(heading)) / iv.curvature;
      y -= (std::cos(heading + turn) - std::cos(heading)) / iv.curvature;
    }
    heading = normalize_angle(heading + turn);
    out.push_back({x, y, direction < 0 ? normalize_angle(heading + kPi) : heading});
  }
}

// The heading averaged over +-`window` waypoints (the window shrinks towards the segment's ends,
// so both end headings stay), each arc's curvature then the heading change over its length. A
// mean over a fixed window has the arcs' curvature averaged too, so within the limit; where the
// window shrinks it may not be, and is clamped to the limit (close_to restores the end heading).
bool averaged(const std::vector<Interval>& in, int window, double max_curvature, std::vector<Interval>& out) {
  const std::size_t n = in.size();
  std::vector<double> heading(n + 1, 0.0), mean(n + 1, 0.0), weight(n + 1, 0.0);
  for (std::size_t j = 0; j < n; ++j) heading[j + 1] = heading[j] + in[j].curvature * in[j].length;
  // Length-weighted: waypoint i stands for the half arcs either side of it.
  for (std::size_t i = 0; i <= n; ++i) {
    weight[i] = 0.5 * ((i > 0 ? in[i - 1].length : 0.0) + (i < n ? in[i].length : 0.0));
  }
  out = in;
  for (std::size_t i = 0; i <= n; ++i) {
    const std::size_t h = std::min({static_cast<std::size_t>(window), i, n - i});
    double sum = 0.0, total = 0.0;
    for (std::size_t j = i - h; j <= i + h; ++j) {
      sum += heading[j] * weight[j];
      total += weight[j];
    }
    mean[i] = h == 0 ? heading[i] : sum / total;
  }
  for (std::size_t j = 0; j < n; ++j) {
    out[j].curvature = std::clamp((mean[j + 1] - mean[j]) / in[j].length, -max_curvature, max_curvature);
  }
  return true;
}

// The end pose [x, y, travel heading] of `intervals` from `start`.
Eigen::Vector3d end_of(const Pose2& start, int direction, const std::vector<Interval>& intervals,
                       std::vector<Pose2>& poses) {
  integrate(start, direction, intervals, poses);
  const Pose2& e = poses.back();
  return {e.x, e.y, travel_heading(e, direction)};
}

// `base` with the correction a applied: curvature + (a0 + a1 (t - 1/2)) x room (t the position
// along the segment in [0, 1]), every length x (1 + a2).
void corrected(const std::vector<Interval>& base, const std::vector<double>& room, const std::vector<double>& t,
               const Eigen::Vector3d& a, std::vector<Interval>& out) {
  out = base;
  for (std::size_t j = 0; j < base.size(); ++j) {
    out[j].curvature += (a.x() + a.y() * (t[j] - 0.5)) * room[j];
    out[j].length *= 1.0 + a.z();
  }
}

// Corrects the smoothed arcs so that integrating them from `start` ends on `end` (position and
// heading): Gauss-Newton (numerical Jacobian) on three unknowns: two curvature shapes, each at
// every arc a fraction of the room left below the limit there (so a correction below 1 keeps
// every curvature within it), and a common stretch of the arc lengths (the smoothed path is a
// little shorter or longer along the way). False when it needs more than that room or a stretch
// over kMaxStretch.
bool close_to(const Pose2& start, const Pose2& end, int direction, double max_curvature, std::vector<Interval>& k) {
  std::vector<Pose2> poses;
  const std::size_t n = k.size();
  std::vector<double> room(n), t(n);
  double total = 0.0;
  for (const Interval& iv : k) total += iv.length;
  double s = 0.0;
  for (std::size_t j = 0; j < n; ++j) {
    room[j] = std::max(0.0, max_curvature - std::abs(k[j].curvature));
    t[j] = (s + 0.5 * k[j].length) / total;
    s += k[j].length;
  }
  const Eigen::Vector3d target(end.x, end.y, travel_heading(end, direction));
  const auto error = [&](const Eigen::Vector3d& e) {
    Eigen::Vector3d r = target - e;
    r.z() = normalize_angle(r.z());
    return r;
  };
  const std::vector<Interval> base = k;
  std::vector<Interval> trial;
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  for (int round = 0; round < kCloseRounds; ++round) {
    corrected(base, room, t, a, trial);
    const Eigen::Vector3d r = error(end_of(start, direction, trial, poses));
    if (r.head<2>().norm() < kClosed && std::abs(r.z()) < kClosed) {
      k = trial;
      return true;
    }
    Eigen::Matrix3d jac;
    for (int m = 0; m < 3; ++m) {
      Eigen::Vector3d da = a;
      da[m] += kJacobianStep;
      corrected(base, room, t, da, trial);
      jac.col(m) = (error(end_of(start, direction, trial, poses)) - r) / -kJacobianStep;
    }
    const Eigen::FullPivLU<Eigen::Matrix3d> lu(jac);
    if (lu.rank() < 3) return false;
    a += lu.solve(r);
    if (std::abs(a.x()) + 0.5 * std::abs(a.y()) > 1.0 || std::abs(a.z()) > kMaxStretch) return false;
  }
  return false;
}

bool within_curvature(const std::vector<Vec2>& p, double max_curvature) {
  const double limit = max_curvature * (1.0 + kCurvatureTolerance);
  for (std::size_t i = 1; i + 1 < p.size(); ++i) {
    if (std::abs(three_point_curvature(p[i - 1], p[i], p[i + 1])) > limit) return false;
  }
  return true;
}

Pose2 interpolate(const Pose2& a, const Pose2& b, double t) {
  const double dyaw = normalize_angle(b.yaw - a.yaw);
  return {a.x + t * (b.x - a.x), a.y + t * (b.y - a.y), normalize_angle(a.yaw + t * dyaw)};
}

// The motion a -> b (position and heading linear) is free for the ungrown footprint. `grown` has
// the footprint grown by `margin`, `lever` is the farthest footprint point from the rear axle.
bool motion_free(const Pose2& a, const Pose2& b, const GridCollisionChecker& grown, double margin, double lever) {
  const double total = std::hypot(b.x - a.x, b.y - a.y) + lever * std::abs(normalize_angle(b.yaw - a.yaw));
  double t = 0.0;
  while (true) {
    const Pose2 pose = t == 0.0 ? a : interpolate(a, b, t);
    double bound = 0.0;
    if (grown.collides(pose, bound)) return false;
    // The next sample may be as far as this one's bound plus both samples' margins (see the header).
    const double step = kSafety * (bound + 2.0 * margin);
    if (total <= 0.0 || (1.0 - t) * total <= step) return !grown.collides(b);
    t += step / total;
  }
}

bool segment_free(const std::vector<Pose2>& poses, const GridCollisionChecker& grown, double margin, double lever) {
  for (std::size_t i = 1; i < poses.size(); ++i) {
    if (!motion_free(poses[i - 1], poses[i], grown, margin, lever)) return false;
  }
  return true;
}

}  // namespace

double three_point_curvature(const Vec2& a, const Vec2& b, const Vec2& c) {
  const Vec2 ab = b - a;
  const Vec2 bc = c - b;
  const Vec2 ac = c - a;
  const double cross = ab.x() * bc.y() - ab.y() * bc.x();  // twice the signed triangle area
  const double denominator = ab.norm() * bc.norm() * ac.norm();
  if (denominator <= 1e-12) return 0.0;
  return 2.0 * cross / denominator;
}

SmoothedPath smooth_path(const std::vector<Waypoint>& waypoints, const GridCollisionChecker& checker,
                         const PathSmootherConfig& config, const StopCondition& stop) {
  SmoothedPath out;
  out.waypoints = waypoints;
  const Footprint& fp = checker.footprint();
  const double margin = config.sweep_margin > 0.0 ? config.sweep_margin : checker.costmap().resolution() / 8.0;
  const Footprint grown_fp{fp.front + margin, fp.rear + margin, fp.left + margin, fp.right + margin};
  const GridCollisionChecker grown(checker.costmap(), grown_fp);
  const double lever = std::hypot(std::max(fp.front, fp.rear), std::max(fp.left, fp.right));

  std::vector<Interval> input, smoothed;
  std::vector<Pose2> poses;
  std::vector<Vec2> points;
  for (const auto& [first, last] : direction_segments(waypoints)) {
    ++out.segments;
    const std::size_t n = last - first + 1;
    if (n < 4) continue;
    if (stop.should_stop()) break;
    const int direction = waypoints[last].direction;
    if (!intervals_of(waypoints, first, last, direction, input)) {
      ++out.refused;
      continue;
    }
    // The widest window that gives a path within the limits, else the input.
    bool accepted = false;
    for (int window = config.window; window >= 1 && !accepted; window /= 2) {
      if (!averaged(input, window, config.max_curvature, smoothed)) continue;
      if (!close_to(waypoints[first].pose, waypoints[last].pose, direction, config.max_curvature, smoothed)) continue;
      integrate(waypoints[first].pose, direction, smoothed, poses);
      poses.back() = waypoints[last].pose;  // the cusp bit for bit (it is within 1e-9 m)
      points.clear();
      for (const Pose2& pose : poses) points.emplace_back(pose.x, pose.y);
      if (!within_curvature(points, config.max_curvature)) continue;
      if (!segment_free(poses, grown, margin, lever)) continue;
      bool changed = false;
      for (std::size_t i = 0; i < n; ++i) {
        const Pose2& o = waypoints[first + i].pose;
        changed = changed || std::abs(poses[i].x - o.x) > 1e-6 || std::abs(poses[i].y - o.y) > 1e-6;
        out.waypoints[first + i].pose = poses[i];
      }
      accepted = true;
      if (changed) ++out.smoothed;
    }
    if (!accepted) ++out.refused;
  }
  return out;
}

PathShape path_shape(const std::vector<Waypoint>& w) {
  PathShape shape;
  for (std::size_t i = 1; i < w.size(); ++i) {
    shape.length += std::hypot(w[i].pose.x - w[i - 1].pose.x, w[i].pose.y - w[i - 1].pose.y);
  }
  for (const auto& [first, last] : direction_segments(w)) {
    if (last + 1 < w.size()) ++shape.cusps;
    double previous = 0.0;
    for (std::size_t i = first + 1; i < last; ++i) {
      const Vec2 a{w[i - 1].pose.x, w[i - 1].pose.y};
      const Vec2 b{w[i].pose.x, w[i].pose.y};
      const double k = three_point_curvature(a, b, {w[i + 1].pose.x, w[i + 1].pose.y});
      shape.max_curvature = std::max(shape.max_curvature, std::abs(k));
      if (i > first + 1) {
        const double dk = k - previous;
        const double ds = std::max(1e-9, (b - a).norm());
        shape.curvature_variation += std::abs(dk);
        shape.max_curvature_rate = std::max(shape.max_curvature_rate, std::abs(dk) / ds);
        shape.curvature_energy += dk * dk / ds;
      }
      previous = k;
    }
  }
  return shape;
}

}  // namespace pullout
