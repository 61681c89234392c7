#include "pullout/freespace/grid_collision_checker.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

namespace pullout {

namespace {

constexpr double kInvSqrt2 = 0.70710678118654752440;
constexpr int kMaxRows = 64;          // rows of a piece kept on the stack (pieces have ~20)
constexpr int kMaxPieces = 8;         // pieces along each side of the rectangle at most
constexpr double kPieceCells = 12.0;  // [cells] the pieces' target side
// [m] pieces of sweep_collides along the body: measured, the hull of a 1.2 m piece's places
// 0.06 rad apart lies within ~1 cm of its true sweep (the whole body's within ~5 cm)
constexpr double kSweepPieceLength = 1.2;

// The cells whose closed interval [i, i + 1] contains the grid coordinate v >= 0 (inside the grid,
// so truncation is floor): from cell_first(v) to cell_last(v); two cells when v is an integer.
inline int cell_last(double v) { return static_cast<int>(v); }
inline int cell_first(double v) {
  const int i = static_cast<int>(v);
  return static_cast<double>(i) == v ? i - 1 : i;
}

// True when an occupied cell meets the convex polygon q (count vertices in order, grid frame in
// cell units, inside the grid) in the rows j0..j1, which cover the rows its y extent touches.
// With `partial` (a costmap with an exact layer), only a hard cell counts; the shapes of the
// partial cells met are appended to *partial for the caller's exact test.
bool polygon_hits(const Costmap& m, const Vec2* q, std::size_t count, int j0, int j1,
                  std::vector<std::uint32_t>* partial) {
  const int rows = j1 - j0 + 1;
  // Each edge adds its exact x range within every row strip it crosses; a convex polygon's extent
  // in a strip is the union of its edges' ranges there (a strip that cuts the polygon cuts its
  // boundary on both sides). The ranges live on the stack unless the piece is unusually tall.
  std::array<double, 2 * static_cast<std::size_t>(kMaxRows)> stack;
  std::vector<double> heap;
  double* lo = stack.data();
  if (rows > kMaxRows) {
    heap.resize(2 * static_cast<std::size_t>(rows));
    lo = heap.data();
  }
  double* hi = lo + rows;
  std::fill_n(lo, rows, std::numeric_limits<double>::infinity());
  std::fill_n(hi, rows, -std::numeric_limits<double>::infinity());
  const auto add = [&](int j, double xa, double xb) {
    if (j < j0 || j > j1) return;
    const auto r = static_cast<std::size_t>(j - j0);
    lo[r] = std::min(lo[r], std::min(xa, xb));
    hi[r] = std::max(hi[r], std::max(xa, xb));
  };
  for (std::size_t i = 0; i < count; ++i) {
    const Vec2& a = q[i];
    const Vec2& b = q[i + 1 == count ? 0 : i + 1];
    const double ya = std::min(a.y(), b.y());
    const double yb = std::max(a.y(), b.y());
    const int ja = cell_last(ya);
    const int jb = cell_last(yb);
    const bool on_boundary = static_cast<double>(ja) == ya;  // then the edge touches row ja - 1 too
    if (yb == ya) {
      add(ja, a.x(), b.x());
      if (on_boundary) add(ja - 1, a.x(), b.x());
      continue;
    }
    const double slope = (b.x() - a.x()) / (b.y() - a.y());
    // Row j's part runs from y = max(ya, j) to min(yb, j + 1): from ya in the first row, j
    // between rows, to yb in the last. Each x is computed once and serves both rows it bounds
    // (the same expression, so the same value as computing it per row).
    const double x_start = a.x() + (ya - a.y()) * slope;
    double x_prev = x_start;
    if (ja >= j0 && jb <= j1) {
      // All of the edge's rows are in range (always, but at the grid's bottom row): no row test.
      // Rounding is monotone, so x grows with y along the edge when slope >= 0 and shrinks when
      // it is negative: which end of a row's part is its minimum is known.
      double* row_lo = lo + (ja - j0);
      double* row_hi = hi + (ja - j0);
      const bool rising = slope >= 0.0;
      for (int j = ja; j < jb; ++j, ++row_lo, ++row_hi) {
        const double x_next = a.x() + ((j + 1.0) - a.y()) * slope;
        *row_lo = std::min(*row_lo, rising ? x_prev : x_next);
        *row_hi = std::max(*row_hi, rising ? x_next : x_prev);
        x_prev = x_next;
      }
    } else {
      for (int j = ja; j < jb; ++j) {
        const double x_next = a.x() + ((j + 1.0) - a.y()) * slope;
        add(j, x_prev, x_next);
        x_prev = x_next;
      }
    }
    add(jb, x_prev, a.x() + (yb - a.y()) * slope);
    if (on_boundary) add(ja - 1, x_start, x_start);
  }
  for (int r = 0; r < rows; ++r) {
    const auto k = static_cast<std::size_t>(r);
    if (lo[k] > hi[k]) continue;
    // The cells the closed range [lo, hi] touches (a range ending on a cell boundary touches the
    // cell beyond it).
    const int j = j0 + r;
    const int c0 = std::max(0, cell_first(lo[k]));
    const int c1 = cell_last(hi[k]);
    if (m.occupied_in_row_inside(c0, c1, j) == 0) continue;
    if (partial == nullptr || m.hard_in_row_inside(c0, c1, j) > 0) return true;
    m.partial_shapes_in_row(c0, c1, j, *partial);
  }
  return false;
}

// Exact test of the closed convex polygon q (count vertices, counter-clockwise, grid frame)
// against the closed segment [p, r]: true when they share a point. Separating axes: the polygon's
// edge normals and the segment's normal (touching is no separation).
bool segment_meets_convex(const Vec2* q, std::size_t count, const Vec2& p, const Vec2& r) {
  for (std::size_t i = 0; i < count; ++i) {
    const Vec2& a = q[i];
    const Vec2& b = q[i + 1 == count ? 0 : i + 1];
    const Vec2 n(b.y() - a.y(), a.x() - b.x());  // outward for a counter-clockwise polygon
    const double limit = n.dot(a);
    if (n.dot(p) > limit && n.dot(r) > limit) return false;
  }
  const Vec2 d = r - p;
  const Vec2 n(-d.y(), d.x());
  const double at = n.dot(p);
  bool below = false;
  bool above = false;
  for (std::size_t i = 0; i < count; ++i) {
    const double v = n.dot(q[i]);
    below = below || v <= at;
    above = above || v >= at;
  }
  return below && above;
}

// The exact test of the convex polygon q (counter-clockwise, grid frame) against the shapes listed
// (indices into m.shapes(), any order, duplicates allowed): true when it meets one of them or
// leaves the drivable polygons.
bool shapes_hit(const Costmap& m, const Vec2* q, std::size_t count, std::vector<std::uint32_t>& ids) {
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  Vec2 centre(0.0, 0.0);
  for (std::size_t i = 0; i < count; ++i) centre += q[i];
  centre /= static_cast<double>(count);
  for (const std::uint32_t id : ids) {
    const Costmap::Shape& s = m.shapes()[id];
    const std::size_t n = s.points.size();
    const std::size_t edges = s.closed ? n : std::max<std::size_t>(1, n - 1);
    for (std::size_t k = 0; k < edges; ++k) {
      if (segment_meets_convex(q, count, s.points[k], s.points[(k + 1) % n])) return true;
    }
    // No edge meets the polygon: it is inside the shape entirely or not at all.
    if (s.closed && point_in_polygon(s.points, centre)) return true;
  }
  // No lane edge meets it either: inside the lanes entirely or not at all.
  return !m.inside_drivable(centre);
}

// The convex hull of pts (counter-clockwise, collinear points dropped) into out; its size.
// Andrew's monotone chain.
std::size_t convex_hull(std::array<Vec2, 8>& pts, std::array<Vec2, 16>& out) {
  std::sort(pts.begin(), pts.end(),
            [](const Vec2& a, const Vec2& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); });
  const auto turn = [](const Vec2& o, const Vec2& a, const Vec2& b) {
    return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
  };
  std::size_t k = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {  // lower hull
    while (k >= 2 && turn(out[k - 2], out[k - 1], pts[i]) <= 0.0) --k;
    out[k++] = pts[i];
  }
  for (std::size_t i = pts.size() - 1, lower = k + 1; i-- > 0;) {  // upper hull
    while (k >= lower && turn(out[k - 2], out[k - 1], pts[i]) <= 0.0) --k;
    out[k++] = pts[i];
  }
  return k - 1;  // the last point repeats the first
}

}  // namespace

GridCollisionChecker::GridCollisionChecker(const Costmap& costmap, const Footprint& footprint)
    : costmap_(costmap), footprint_(footprint) {
  origin_x_ = costmap.origin().x;
  origin_y_ = costmap.origin().y;
  origin_cos_ = std::cos(costmap.origin().yaw);
  origin_sin_ = std::sin(costmap.origin().yaw);
  inv_resolution_ = 1.0 / costmap.resolution();
  grid_width_ = costmap.width();
  grid_height_ = costmap.height();
  // Discs of radius r along the centre line cover the rectangle when each covers a slice of
  // length 2 * sqrt(r^2 - half_width^2). Slices of about 0.4 widths keep r within ~8 % of the
  // half width.
  const double half_width = 0.5 * footprint.width();
  const int n = std::max(1, static_cast<int>(std::ceil(2.5 * footprint.length() / std::max(footprint.width(), 1e-3))));
  const double slice = footprint.length() / n;
  disc_count_ = n;
  disc_first_x_ = -footprint.rear + 0.5 * slice;
  disc_step_ = slice;
  disc_radius_ = std::hypot(0.5 * slice, half_width);
  disc_offset_y_ = 0.5 * (footprint.left - footprint.right);
  constexpr double kSafety = 1e-4;  // [m] covers the float rounding of the stored distances
  bound_margin_ = disc_radius_ + kInvSqrt2 * costmap.resolution() + kSafety;
  // Pieces of about kPieceCells cells a side: small enough that most of a piece's bounding box
  // (at most twice its area) lies near the piece, large enough to keep the box lookups few.
  const double piece = kPieceCells * costmap.resolution();
  const auto pieces = [&](double side) { return std::clamp(static_cast<int>(std::ceil(side / piece)), 1, kMaxPieces); };
  pieces_x_ = pieces(footprint.length());
  pieces_y_ = pieces(footprint.width());
  sweep_pieces_ = std::clamp(static_cast<int>(std::ceil(footprint.length() / kSweepPieceLength)), 1, kMaxPieces);
}

double GridCollisionChecker::sweep_factor(double curvature) const {
  // A body point at (x, y) from the rear axle moves with speed |v| * |(1 - k y, k x)|.
  const double k = std::abs(curvature);
  const double far_x = std::max(footprint_.front, footprint_.rear);
  const double far_y = std::max(footprint_.left, footprint_.right);
  const double a = 1.0 + k * far_y;
  const double b = k * far_x;
  return std::sqrt(a * a + b * b);
}

inline GridCollisionChecker::GridPose GridCollisionChecker::grid_pose(const Pose2& pose, double c, double s) const {
  // Costmap::to_grid with the heading rotated along (X_GV = X_MG^-1 X_MV), cell units.
  const double dx = pose.x - origin_x_;
  const double dy = pose.y - origin_y_;
  return {(origin_cos_ * dx + origin_sin_ * dy) * inv_resolution_,
          (origin_cos_ * dy - origin_sin_ * dx) * inv_resolution_,
          (origin_cos_ * c + origin_sin_ * s) * inv_resolution_, (origin_cos_ * s - origin_sin_ * c) * inv_resolution_};
}

double GridCollisionChecker::clearance_lower_bound(const Pose2& pose) const {
  return clearance_bound(grid_pose(pose, std::cos(pose.yaw), std::sin(pose.yaw)));
}

double GridCollisionChecker::clearance_bound(const GridPose& g) const {
  // For a disc centre p in cell k (centre q_k): every occupied square is at least
  // D(k) - |p - q_k| - res / sqrt2 away (D: centre distance to the nearest occupied centre; 0 on
  // an occupied cell), so the disc is at least that minus its radius away.
  const double res = costmap_.resolution();
  // Disc centres in the grid frame: the first one, then a constant step along the axis.
  double px = g.x + disc_first_x_ * g.ux - disc_offset_y_ * g.uy;
  double py = g.y + disc_first_x_ * g.uy + disc_offset_y_ * g.ux;
  const double step_x = disc_step_ * g.ux;
  const double step_y = disc_step_ * g.uy;
  double best = std::numeric_limits<double>::infinity();
  for (int k = 0; k < disc_count_; ++k, px += step_x, py += step_y) {
    // A centre outside the grid: the footprint leaves it (also catches NaN).
    if (!(px >= 0.0 && py >= 0.0 && px < grid_width_ && py < grid_height_)) return 0.0;
    const int ix = static_cast<int>(px);
    const int iy = static_cast<int>(py);
    const double ox = std::abs(px - ix - 0.5);
    const double oy = std::abs(py - iy - 0.5);
    const double off = std::sqrt(ox * ox + oy * oy) * res;
    best = std::min(best, costmap_.centre_distance(ix, iy) - off);
    if (best <= bound_margin_) return 0.0;
  }
  return best - bound_margin_;
}

bool GridCollisionChecker::collides(const Pose2& pose) const {
  double bound = 0.0;
  return collides(pose, bound);
}

bool GridCollisionChecker::collides(const Pose2& pose, double& bound) const {
  return collides(pose, std::cos(pose.yaw), std::sin(pose.yaw), bound);
}

bool GridCollisionChecker::collides(const Pose2& pose, double c, double s, double& bound) const {
  const GridPose g = grid_pose(pose, c, s);
  bound = clearance_bound(g);
  if (bound > 0.0) return false;
  return collides_exact(g);
}

bool GridCollisionChecker::collides_exact(const GridPose& g) const {
  const Footprint& f = footprint_;
  // The rectangle cut into pieces_x_ x pieces_y_ equal pieces: lattice offsets from the rear axle
  // along the axis (a_i * u) and across it (b_k * v, v = u turned left), grid frame. The outer
  // lattice lines are the rectangle's sides exactly; neighbouring pieces share their lattice
  // points, so the closed pieces cover the closed rectangle without gaps.
  const int nx = pieces_x_;
  const int ny = pieces_y_;
  std::array<double, kMaxPieces + 1> ax;
  std::array<double, kMaxPieces + 1> ay;
  std::array<double, kMaxPieces + 1> bx;
  std::array<double, kMaxPieces + 1> by;
  for (int i = 0; i <= nx; ++i) {
    const double a = i == nx ? f.front : -f.rear + i * (f.length() / nx);
    ax[static_cast<std::size_t>(i)] = a * g.ux;
    ay[static_cast<std::size_t>(i)] = a * g.uy;
  }
  for (int k = 0; k <= ny; ++k) {
    const double b = k == ny ? f.left : -f.right + k * (f.width() / ny);
    bx[static_cast<std::size_t>(k)] = -b * g.uy;
    by[static_cast<std::size_t>(k)] = b * g.ux;
  }
  const auto point = [&](int i, int k) {
    return Vec2{g.x + ax[static_cast<std::size_t>(i)] + bx[static_cast<std::size_t>(k)],
                g.y + ay[static_cast<std::size_t>(i)] + by[static_cast<std::size_t>(k)]};
  };
  const auto bounds = [](const std::array<Vec2, 4>& q, double& x_lo, double& y_lo, double& x_hi, double& y_hi) {
    x_lo = std::min(std::min(q[0].x(), q[1].x()), std::min(q[2].x(), q[3].x()));
    x_hi = std::max(std::max(q[0].x(), q[1].x()), std::max(q[2].x(), q[3].x()));
    y_lo = std::min(std::min(q[0].y(), q[1].y()), std::min(q[2].y(), q[3].y()));
    y_hi = std::max(std::max(q[0].y(), q[1].y()), std::max(q[2].y(), q[3].y()));
  };
  const std::array<Vec2, 4> corners{point(0, 0), point(nx, 0), point(nx, ny), point(0, ny)};
  double x_lo = 0.0;
  double y_lo = 0.0;
  double x_hi = 0.0;
  double y_hi = 0.0;
  bounds(corners, x_lo, y_lo, x_hi, y_hi);
  // Outside the grid is occupied (a touch of the far edge counts: cell `width` is outside). NaN
  // fails the test too.
  if (!(x_lo >= 0.0 && y_lo >= 0.0 && x_hi < grid_width_ && y_hi < grid_height_)) return true;
  // Any cell the rectangle touches, touches its bounding box: an empty box is no collision.
  const auto box_empty = [&](double bx_lo, double by_lo, double bx_hi, double by_hi, int& j0, int& j1) {
    j0 = std::max(0, cell_first(by_lo));
    j1 = cell_last(by_hi);
    return costmap_.occupied_in_box_inside(std::max(0, cell_first(bx_lo)), j0, cell_last(bx_hi), j1) == 0;
  };
  int j0 = 0;
  int j1 = 0;
  if (box_empty(x_lo, y_lo, x_hi, y_hi, j0, j1)) return false;
  // With an exact layer, partial cells collect their shapes for the exact test at the end.
  std::vector<std::uint32_t> shapes;
  std::vector<std::uint32_t>* partial = costmap_.has_partial() ? &shapes : nullptr;
  if (nx * ny == 1) {
    if (polygon_hits(costmap_, corners.data(), 4, j0, j1, partial)) return true;
  } else {
    // Otherwise only the pieces whose own box holds an occupied cell need the exact row walk.
    for (int i = 0; i < nx; ++i) {
      for (int k = 0; k < ny; ++k) {
        const std::array<Vec2, 4> q{point(i, k), point(i + 1, k), point(i + 1, k + 1), point(i, k + 1)};
        bounds(q, x_lo, y_lo, x_hi, y_hi);
        if (box_empty(x_lo, y_lo, x_hi, y_hi, j0, j1)) continue;
        if (polygon_hits(costmap_, q.data(), 4, j0, j1, partial)) return true;
      }
    }
  }
  if (shapes.empty()) return false;
  // counter-clockwise for shapes_hit (corners run rear-right, front-right, front-left, rear-left)
  return shapes_hit(costmap_, corners.data(), corners.size(), shapes);
}

double GridCollisionChecker::sweep_margin(double curvature, double turn) const {
  if (std::abs(curvature) < 1e-12) return 0.0;
  // The farthest corner from the turning centre (0, 1 / curvature) in the vehicle frame.
  const double cy = 1.0 / curvature;
  const double far_x = std::max(footprint_.front, footprint_.rear);
  const double far_y = std::max(std::abs(footprint_.left - cy), std::abs(-footprint_.right - cy));
  return std::hypot(far_x, far_y) * (1.0 - std::cos(0.5 * std::abs(turn)));
}

bool GridCollisionChecker::sweep_collides(const Pose2& a, const Pose2& b, double margin) const {
  return sweep_collides(a, std::cos(a.yaw), std::sin(a.yaw), b, std::cos(b.yaw), std::sin(b.yaw), margin);
}

bool GridCollisionChecker::sweep_collides(const Pose2& a, double cos_a, double sin_a, const Pose2& b, double cos_b,
                                          double sin_b, double margin) const {
  const Footprint& f = footprint_;
  const GridPose ga = grid_pose(a, cos_a, sin_a);
  const GridPose gb = grid_pose(b, cos_b, sin_b);
  const double m = margin * inv_resolution_;
  std::vector<std::uint32_t> shapes;
  // Piece by piece along the body: the hull of a short piece's two places hugs its sweep much
  // closer than the hull of the whole body (which fills in the inside of a turn).
  const int pieces = sweep_pieces_;
  for (int piece = 0; piece < pieces; ++piece) {
    const double x0 = -f.rear + f.length() * piece / pieces;
    const double x1 = piece + 1 == pieces ? f.front : -f.rear + f.length() * (piece + 1) / pieces;
    std::array<Vec2, 8> pts;
    std::size_t n = 0;
    for (const GridPose* g : {&ga, &gb}) {
      for (const auto& [x, y] :
           {std::pair{x0, -f.right}, std::pair{x1, -f.right}, std::pair{x1, f.left}, std::pair{x0, f.left}}) {
        pts[n++] = Vec2(g->x + x * g->ux - y * g->uy, g->y + x * g->uy + y * g->ux);
      }
    }
    // Most pieces pass through free space: the box of the eight corners grown by 2 m holds the
    // grown hull below (its vertices move at most m sqrt 2), so when that box lies inside the
    // grid and holds no occupied cell, the hull's own box would too and the piece is free, as
    // the test below would find, without the hull.
    {
      double bx_lo = pts[0].x();
      double bx_hi = bx_lo;
      double by_lo = pts[0].y();
      double by_hi = by_lo;
      for (std::size_t i = 1; i < n; ++i) {
        bx_lo = std::min(bx_lo, pts[i].x());
        bx_hi = std::max(bx_hi, pts[i].x());
        by_lo = std::min(by_lo, pts[i].y());
        by_hi = std::max(by_hi, pts[i].y());
      }
      const double grow = 2.0 * m + 1e-9;
      bx_lo -= grow;
      by_lo -= grow;
      bx_hi += grow;
      by_hi += grow;
      if (bx_lo >= 0.0 && by_lo >= 0.0 && bx_hi < grid_width_ && by_hi < grid_height_ &&
          costmap_.occupied_in_box_inside(std::max(0, cell_first(bx_lo)), std::max(0, cell_first(by_lo)),
                                          cell_last(bx_hi), cell_last(by_hi)) == 0) {
        continue;
      }
    }
    std::array<Vec2, 16> hull;
    const std::size_t count = convex_hull(pts, hull);
    // Grown by the margin: each edge moved out by it, each vertex to where its two edges now meet
    // (the hull's angles are at least the footprint's right angles, so a vertex moves at most
    // margin * sqrt 2). That polygon holds every point within `margin` of the hull.
    std::array<Vec2, 16> grown;
    double x_lo = std::numeric_limits<double>::infinity();
    double x_hi = -x_lo;
    double y_lo = x_lo;
    double y_hi = -x_lo;
    for (std::size_t i = 0; i < count; ++i) {
      const Vec2& v = hull[i];
      const Vec2 e0 = (v - hull[(i + count - 1) % count]).normalized();
      const Vec2 e1 = (hull[(i + 1) % count] - v).normalized();
      const Vec2 n0(e0.y(), -e0.x());
      const Vec2 n1(e1.y(), -e1.x());
      grown[i] = v + m * (n0 + n1) / (1.0 + n0.dot(n1));
      x_lo = std::min(x_lo, grown[i].x());
      x_hi = std::max(x_hi, grown[i].x());
      y_lo = std::min(y_lo, grown[i].y());
      y_hi = std::max(y_hi, grown[i].y());
    }
    if (!(x_lo >= 0.0 && y_lo >= 0.0 && x_hi < grid_width_ && y_hi < grid_height_)) return true;
    const int j0 = std::max(0, cell_first(y_lo));
    const int j1 = cell_last(y_hi);
    if (costmap_.occupied_in_box_inside(std::max(0, cell_first(x_lo)), j0, cell_last(x_hi), j1) == 0) continue;
    shapes.clear();
    std::vector<std::uint32_t>* partial = costmap_.has_partial() ? &shapes : nullptr;
    if (polygon_hits(costmap_, grown.data(), count, j0, j1, partial)) return true;
    if (!shapes.empty() && shapes_hit(costmap_, grown.data(), count, shapes)) return true;
  }
  return false;
}

}  // namespace pullout
