// 2D geometry on Eigen: vectors, angles and polylines with arc length.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <vector>

#include "pullout/geometry/angle.hpp"
#include "pullout/model/types.hpp"

namespace pullout {

using Vec2 = Eigen::Vector2d;

inline Vec2 to_vec(const Point2& p) { return {p.x, p.y}; }
inline Vec2 to_vec(const Pose2& p) { return {p.x, p.y}; }
inline Point2 to_point(const Vec2& v) { return {v.x(), v.y()}; }
inline Vec2 heading(double yaw);  // unit vector
inline Vec2 left_normal(const Vec2& unit) { return {-unit.y(), unit.x()}; }

// Length [m] of the line through `points` in order (0 with fewer than two points).
double polyline_length(const std::vector<Point2>& points);
// Length [m] of the line through the positions of a path's points, in order.
double polyline_length(const PathWithLaneId& path);

// Position of point p in the frame of `pose`: (longitudinal, lateral-left) [m].
Vec2 to_local(const Pose2& pose, const Vec2& p);
// Inverse of to_local.
Vec2 to_global(const Pose2& pose, const Vec2& p_local);

// A polyline with cumulative arc length. Consecutive duplicate points (closer than 1e-6 m) are
// dropped at construction. Headings are defined at vertices as the mean direction of the adjacent
// segments, so that headings interpolated along the line are continuous.
class Polyline {
 public:
  Polyline() = default;
  explicit Polyline(const std::vector<Vec2>& points);

  std::size_t size() const { return points_.size(); }
  bool empty() const { return points_.empty(); }
  const std::vector<Vec2>& points() const { return points_; }
  const Vec2& point(std::size_t i) const { return points_[i]; }
  double s(std::size_t i) const { return s_[i]; }
  double length() const { return s_.empty() ? 0.0 : s_.back(); }

  // Index of the segment [i, i+1] containing arc length s (clamped to the line; NaN gives 0).
  std::size_t segment_at(double s) const;
  // Point at arc length s; beyond the ends the end segments are extended linearly.
  Vec2 point_at(double s) const;
  // Heading [rad] at s, interpolated between vertex headings (clamped to the line).
  double yaw_at(double s) const;
  Pose2 pose_at(double s) const;
  // pose_at and curvature_at with one segment lookup.
  struct Sample {
    Pose2 pose;
    double curvature{0.0};
  };
  Sample sample_at(double s) const;
  // Signed curvature [1/m] at s, interpolated between vertex curvatures (Menger curvature of each
  // vertex with its neighbours; 0 at the end points).
  double curvature_at(double s) const;

  struct Projection {
    double s{0.0};         // arc length of the foot point (extrapolated beyond the ends)
    double lateral{0.0};   // signed offset, left of the line positive [m]
    double distance{0.0};  // Euclidean distance to the nearest point of the line [m]
    std::size_t segment{0};
  };
  // Projection of p on the nearest segment. Requires size() >= 2.
  Projection project(const Vec2& p) const;

  // Points every `interval` metres from s0 to s1 (both included, s1 - last step may be shorter).
  Polyline resampled(double interval, double s0, double s1) const;
  Polyline resampled(double interval) const { return resampled(interval, 0.0, length()); }

 private:
  std::vector<Vec2> points_;
  std::vector<double> s_;
  std::vector<double> vertex_yaw_;
  std::vector<double> vertex_curvature_;
};

inline Vec2 heading(double yaw) { return {std::cos(yaw), std::sin(yaw)}; }

}  // namespace pullout
