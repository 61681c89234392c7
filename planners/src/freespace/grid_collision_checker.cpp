#include "pullout/freespace/grid_collision_checker.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace pullout {

namespace {

constexpr double kInvSqrt2 = 0.70710678118654752440;
constexpr int kMaxRows = 512;  // rows of a footprint handled on the stack; beyond: strip by strip

}  // namespace

GridCollisionChecker::GridCollisionChecker(const Costmap& costmap, const Footprint& footprint)
    : costmap_(costmap), footprint_(footprint) {
  // Discs of radius r along the centre line cover the rectangle when each covers a slice of
  // length 2 * sqrt(r^2 - half_width^2). Slices of about 0.4 widths keep r within ~8 % of the
  // half width.
  const double half_width = 0.5 * footprint.width();
  const int n = std::max(1, static_cast<int>(std::ceil(2.5 * footprint.length() / std::max(footprint.width(), 1e-3))));
  const double slice = footprint.length() / n;
  disc_radius_ = std::hypot(0.5 * slice, half_width);
  for (int i = 0; i < n; ++i) disc_x_.push_back(-footprint.rear + (i + 0.5) * slice);
  disc_offset_y_ = 0.5 * (footprint.left - footprint.right);
}

double GridCollisionChecker::sweep_factor(double curvature) const {
  // A body point at (x, y) from the rear axle moves with speed |v| * |(1 - k y, k x)|.
  const double k = std::abs(curvature);
  const double far_x = std::max(footprint_.front, footprint_.rear);
  const double far_y = std::max(footprint_.left, footprint_.right);
  return std::hypot(1.0 + k * far_y, k * far_x);
}

double GridCollisionChecker::clearance_lower_bound(const Pose2& pose) const {
  return clearance_bound(pose, std::cos(pose.yaw), std::sin(pose.yaw));
}

double GridCollisionChecker::clearance_bound(const Pose2& pose, double c, double s) const {
  // For a disc centre p in cell k (centre q_k): every occupied square is at least
  // D(k) - |p - q_k| - res / sqrt2 away (D: centre distance to the nearest occupied centre).
  constexpr double kSafety = 1e-4;  // [m] covers the float rounding of the stored distances
  const double res = costmap_.resolution();
  double best = std::numeric_limits<double>::infinity();
  for (const double x : disc_x_) {
    const Vec2 g = costmap_.to_grid({pose.x + c * x - s * disc_offset_y_, pose.y + s * x + c * disc_offset_y_});
    const double fx = std::floor(g.x());
    const double fy = std::floor(g.y());
    if (fx < 0.0 || fy < 0.0 || fx >= costmap_.width() || fy >= costmap_.height()) return 0.0;
    const int ix = static_cast<int>(fx);
    const int iy = static_cast<int>(fy);
    if (costmap_.occupied(ix, iy)) return 0.0;
    const double ox = g.x() - fx - 0.5;
    const double oy = g.y() - fy - 0.5;
    const double off = std::sqrt(ox * ox + oy * oy) * res;
    best = std::min(best, costmap_.centre_distance(ix, iy) - off - kInvSqrt2 * res - disc_radius_ - kSafety);
    if (best <= 0.0) return 0.0;
  }
  return best;
}

bool GridCollisionChecker::collides(const Pose2& pose) const {
  double bound = 0.0;
  return collides(pose, bound);
}

bool GridCollisionChecker::collides(const Pose2& pose, double& bound) const {
  return collides(pose, std::cos(pose.yaw), std::sin(pose.yaw), bound);
}

bool GridCollisionChecker::collides(const Pose2& pose, double c, double s, double& bound) const {
  bound = clearance_bound(pose, c, s);
  if (bound > 0.0) return false;
  return collides_exact(pose, c, s);
}

bool GridCollisionChecker::collides_exact(const Pose2& pose, double c, double s) const {
  // Corners in the grid frame (cell units), counter-clockwise.
  const Footprint& f = footprint_;
  const std::array<Vec2, 4> local{Vec2{f.front, f.left}, Vec2{-f.rear, f.left}, Vec2{-f.rear, -f.right},
                                  Vec2{f.front, -f.right}};
  std::array<Vec2, 4> g;
  double y_lo = std::numeric_limits<double>::infinity();
  double y_hi = -y_lo;
  double x_lo = y_lo;
  double x_hi = -y_lo;
  for (std::size_t i = 0; i < 4; ++i) {
    g[i] =
        costmap_.to_grid({pose.x + c * local[i].x() - s * local[i].y(), pose.y + s * local[i].x() + c * local[i].y()});
    y_lo = std::min(y_lo, g[i].y());
    y_hi = std::max(y_hi, g[i].y());
    x_lo = std::min(x_lo, g[i].x());
    x_hi = std::max(x_hi, g[i].x());
  }
  // Outside the grid is occupied (a touch of the far edge counts: cell `width` is outside).
  if (x_lo < 0.0 || y_lo < 0.0 || x_hi >= costmap_.width() || y_hi >= costmap_.height()) return true;
  const int j0 = static_cast<int>(std::floor(y_lo));
  const int j1 = static_cast<int>(std::floor(y_hi));
  const int rows = j1 - j0 + 1;
  if (rows > kMaxRows) {
    for (int j = j0; j <= j1; ++j) {
      double a = 0.0;
      double b = 0.0;
      if (!strip_extent(g.data(), 4, j, j + 1.0, a, b)) continue;
      if (costmap_.occupied_in_row(j, static_cast<int>(std::floor(a)), static_cast<int>(std::floor(b))) > 0) {
        return true;
      }
    }
    return false;
  }
  // Each edge adds its exact x range within every row strip it crosses; a rectangle's extent in
  // a strip is the union of its edges' ranges there (a strip that cuts the rectangle cuts its
  // boundary on both sides).
  std::array<double, kMaxRows> lo;
  std::array<double, kMaxRows> hi;
  std::fill_n(lo.begin(), rows, std::numeric_limits<double>::infinity());
  std::fill_n(hi.begin(), rows, -std::numeric_limits<double>::infinity());
  const auto add = [&](int j, double xa, double xb) {
    if (j < j0 || j > j1) return;
    const auto r = static_cast<std::size_t>(j - j0);
    lo[r] = std::min(lo[r], std::min(xa, xb));
    hi[r] = std::max(hi[r], std::max(xa, xb));
  };
  for (std::size_t i = 0; i < 4; ++i) {
    const Vec2& a = g[i];
    const Vec2& b = g[(i + 1) % 4];
    const double ya = std::min(a.y(), b.y());
    const double yb = std::max(a.y(), b.y());
    const int ja = static_cast<int>(std::floor(ya));
    const int jb = static_cast<int>(std::floor(yb));
    if (yb == ya) {
      add(ja, a.x(), b.x());
      if (ya == ja) add(ja - 1, a.x(), b.x());  // on a row boundary: it touches both rows
      continue;
    }
    const double slope = (b.x() - a.x()) / (b.y() - a.y());
    for (int j = ja; j <= jb; ++j) {
      const double y0 = std::max(ya, static_cast<double>(j));
      const double y1 = std::min(yb, j + 1.0);
      add(j, a.x() + (y0 - a.y()) * slope, a.x() + (y1 - a.y()) * slope);
    }
    if (ya == ja) add(ja - 1, a.x() + (ya - a.y()) * slope, a.x() + (ya - a.y()) * slope);
  }
  for (int r = 0; r < rows; ++r) {
    if (lo[static_cast<std::size_t>(r)] > hi[static_cast<std::size_t>(r)]) continue;
    const int c0 = static_cast<int>(std::floor(lo[static_cast<std::size_t>(r)]));
    const int c1 = static_cast<int>(std::floor(hi[static_cast<std::size_t>(r)]));
    if (costmap_.occupied_in_row(j0 + r, c0, c1) > 0) return true;
  }
  return false;
}

}  // namespace pullout
