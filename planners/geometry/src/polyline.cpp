#include "pullout/geometry/polyline.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pullout {

double polyline_length(const std::vector<Point2>& points) {
  double length = 0.0;
  for (std::size_t i = 1; i < points.size(); ++i) {
    length += std::hypot(points[i].x - points[i - 1].x, points[i].y - points[i - 1].y);
  }
  return length;
}

double polyline_length(const PathWithLaneId& path) {
  double length = 0.0;
  for (std::size_t i = 1; i < path.points.size(); ++i) {
    length += std::hypot(path.points[i].pose.x - path.points[i - 1].pose.x,
                         path.points[i].pose.y - path.points[i - 1].pose.y);
  }
  return length;
}

Vec2 to_local(const Pose2& pose, const Vec2& p) {
  const Vec2 d = p - to_vec(pose);
  const double c = std::cos(pose.yaw);
  const double s = std::sin(pose.yaw);
  return {c * d.x() + s * d.y(), -s * d.x() + c * d.y()};
}

Vec2 to_global(const Pose2& pose, const Vec2& p_local) {
  const double c = std::cos(pose.yaw);
  const double s = std::sin(pose.yaw);
  return {pose.x + c * p_local.x() - s * p_local.y(), pose.y + s * p_local.x() + c * p_local.y()};
}

Polyline::Polyline(const std::vector<Vec2>& points) {
  points_.reserve(points.size());
  for (const Vec2& p : points) {
    if (points_.empty() || (p - points_.back()).norm() > 1e-6) points_.push_back(p);
  }
  const std::size_t n = points_.size();
  s_.assign(n, 0.0);
  for (std::size_t i = 1; i < n; ++i) s_[i] = s_[i - 1] + (points_[i] - points_[i - 1]).norm();

  vertex_yaw_.assign(n, 0.0);
  vertex_curvature_.assign(n, 0.0);
  if (n < 2) return;
  std::vector<double> seg_yaw(n - 1);
  for (std::size_t i = 0; i + 1 < n; ++i) {
    const Vec2 d = points_[i + 1] - points_[i];
    seg_yaw[i] = std::atan2(d.y(), d.x());
  }
  vertex_yaw_[0] = seg_yaw.front();
  vertex_yaw_[n - 1] = seg_yaw.back();
  for (std::size_t i = 1; i + 1 < n; ++i) {
    // Mean direction of the two adjacent segments, weighted equally.
    vertex_yaw_[i] = normalize_angle(seg_yaw[i - 1] + 0.5 * normalize_angle(seg_yaw[i] - seg_yaw[i - 1]));
    // Menger curvature: 2 sin(turn angle) / |chord| equals 1/R of the circle through 3 points.
    const Vec2 a = points_[i - 1];
    const Vec2 b = points_[i];
    const Vec2 c = points_[i + 1];
    const double cross = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
    const double denom = (b - a).norm() * (c - b).norm() * (c - a).norm();
    vertex_curvature_[i] = denom > 1e-12 ? 2.0 * cross / denom : 0.0;
  }
}

std::size_t Polyline::segment_at(double s) const {
  if (points_.size() < 2) return 0;
  if (!(s > 0.0)) return 0;  // also NaN: upper_bound would give the end, one past the last segment
  if (s >= s_.back()) return points_.size() - 2;
  const auto it = std::upper_bound(s_.begin(), s_.end(), s);
  return static_cast<std::size_t>(std::distance(s_.begin(), it)) - 1;
}

Vec2 Polyline::point_at(double s) const {
  if (points_.size() == 1) return points_.front();
  const std::size_t i = segment_at(s);
  const double len = s_[i + 1] - s_[i];
  const double t = (s - s_[i]) / len;  // may be outside [0, 1] on the end segments
  return points_[i] + t * (points_[i + 1] - points_[i]);
}

double Polyline::yaw_at(double s) const {
  if (points_.size() < 2) return 0.0;
  const std::size_t i = segment_at(s);
  const double t = std::clamp((s - s_[i]) / (s_[i + 1] - s_[i]), 0.0, 1.0);
  return normalize_angle(vertex_yaw_[i] + t * normalize_angle(vertex_yaw_[i + 1] - vertex_yaw_[i]));
}

Pose2 Polyline::pose_at(double s) const {
  const Vec2 p = point_at(s);
  return {p.x(), p.y(), yaw_at(s)};
}

Polyline::Sample Polyline::sample_at(double s) const {
  Sample out;
  if (points_.size() < 2) {
    if (!points_.empty()) out.pose = {points_[0].x(), points_[0].y(), 0.0};
    return out;
  }
  const std::size_t i = segment_at(s);
  const double len = s_[i + 1] - s_[i];
  const double t_raw = (s - s_[i]) / len;
  const double t = std::clamp(t_raw, 0.0, 1.0);
  const Vec2 p = points_[i] + t_raw * (points_[i + 1] - points_[i]);
  out.pose = {p.x(), p.y(), normalize_angle(vertex_yaw_[i] + t * normalize_angle(vertex_yaw_[i + 1] - vertex_yaw_[i]))};
  out.curvature = vertex_curvature_[i] + t * (vertex_curvature_[i + 1] - vertex_curvature_[i]);
  return out;
}

double Polyline::curvature_at(double s) const {
  if (points_.size() < 3) return 0.0;
  const std::size_t i = segment_at(s);
  const double t = std::clamp((s - s_[i]) / (s_[i + 1] - s_[i]), 0.0, 1.0);
  return vertex_curvature_[i] + t * (vertex_curvature_[i + 1] - vertex_curvature_[i]);
}

Polyline::Projection Polyline::project(const Vec2& p) const {
  Projection best;
  double best_d2 = std::numeric_limits<double>::infinity();
  const std::size_t n = points_.size();
  for (std::size_t i = 0; i + 1 < n; ++i) {
    const Vec2 a = points_[i];
    const Vec2 d = points_[i + 1] - a;
    const double len2 = d.squaredNorm();
    const double t = std::clamp((p - a).dot(d) / len2, 0.0, 1.0);
    const double d2 = (a + t * d - p).squaredNorm();
    if (d2 < best_d2) {
      best_d2 = d2;
      best.segment = i;
    }
  }
  if (n < 2) return best;
  const std::size_t i = best.segment;
  const Vec2 a = points_[i];
  const Vec2 d = points_[i + 1] - a;
  const double len = d.norm();
  const double t_raw = (p - a).dot(d) / (len * len);
  // Beyond the first/last vertex the end segment is extended, so that s and the lateral offset
  // stay meaningful for points just outside the line.
  const bool extrapolate = (i == 0 && t_raw < 0.0) || (i + 2 == n && t_raw > 1.0);
  const double t = extrapolate ? t_raw : std::clamp(t_raw, 0.0, 1.0);
  best.distance = std::sqrt(best_d2);
  best.s = s_[i] + t * len;
  best.lateral = (d.x() * (p - a).y() - d.y() * (p - a).x()) / len;
  return best;
}

Polyline Polyline::resampled(double interval, double s0, double s1) const {
  std::vector<Vec2> out;
  if (points_.empty() || interval <= 0.0 || s1 < s0) return Polyline(out);
  const auto count = static_cast<std::size_t>(std::floor((s1 - s0) / interval + 1e-9));
  out.reserve(count + 2);
  for (std::size_t k = 0; k <= count; ++k) out.push_back(point_at(s0 + static_cast<double>(k) * interval));
  if (s1 - (s0 + static_cast<double>(count) * interval) > 1e-6) out.push_back(point_at(s1));
  return Polyline(out);
}

}  // namespace pullout
