#include "pullout/freespace/motion_check.hpp"

#include <algorithm>
#include <cmath>

#include "search_support.hpp"

namespace pullout {

namespace fd = freespace_detail;

namespace {

constexpr double kCoarseSpacing = 1.0;  // [m] first-pass sample spacing (a colliding path fails there, cheaply)
constexpr double kZeroSegment = 1e-9;   // [m]

double curvature_of(const ReedsSheppSegment& seg, double turning_radius) {
  return static_cast<double>(static_cast<int>(seg.kind)) / turning_radius;
}

}  // namespace

bool reeds_shepp_path_free(const GridCollisionChecker& checker, double turning_radius, const Pose2& from,
                           const ReedsSheppPath& path) {
  double start_clearance = 0.0;
  if (checker.collides(from, start_clearance)) return false;
  for (const bool fine : {false, true}) {
    Pose2 pose = from;
    double clearance = start_clearance;
    for (int i = 0; i < path.count; ++i) {
      const ReedsSheppSegment& seg = path.segments[static_cast<std::size_t>(i)];
      if (std::abs(seg.length) < kZeroSegment) continue;
      const double k = curvature_of(seg, turning_radius);
      const bool free = fine ? fd::arc_free(checker, fd::Arc(pose, k), clearance, seg.length, clearance)
                             : fd::arc_samples_free(checker, pose, k, seg.length, kCoarseSpacing);
      if (!free) return false;
      pose = fd::drive(pose, k, seg.length);
    }
  }
  return true;
}

Pose2 append_reeds_shepp_waypoints(double turning_radius, const Pose2& from, const ReedsSheppPath& path,
                                   double interval, std::vector<Waypoint>& out) {
  Pose2 pose = from;
  for (int i = 0; i < path.count; ++i) {
    const ReedsSheppSegment& seg = path.segments[static_cast<std::size_t>(i)];
    if (std::abs(seg.length) < kZeroSegment) continue;
    const double k = curvature_of(seg, turning_radius);
    const int dir = seg.length < 0.0 ? -1 : 1;
    const int n = std::max(1, static_cast<int>(std::ceil(std::abs(seg.length) / interval - 1e-9)));
    for (int j = 1; j <= n; ++j) out.push_back({fd::drive(pose, k, seg.length * j / n), dir});
    pose = fd::drive(pose, k, seg.length);
  }
  return pose;
}

}  // namespace pullout
