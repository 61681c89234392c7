#include "pullout/freespace/costmap.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace pullout {

namespace {

constexpr double kSqrt2 = 1.41421356237309504880;

// v (an integral value: a floor or ceil) as an int clamped to [lo, hi]. The comparison comes
// before the conversion, so v may be of any size; NaN gives lo.
int clamped_int(double v, int lo, int hi) {
  if (!(v >= lo)) return lo;
  if (v >= hi) return hi;
  return static_cast<int>(v);
}

// The largest side of a costmap made by from_polygons [cells].
constexpr int kMaxSideCells = 1 << 14;

// Rows or columns between two checks of the stop condition (a row is at most 16384 cells).
constexpr int kStopCheckRows = 64;

bool stop_now(const StopCondition& stop, int line, StopReason& stopped) {
  if (line % kStopCheckRows != 0) return false;
  stopped = stop.check();
  return stopped != StopReason::kNone;
}

}  // namespace

bool strip_extent(const Vec2* vertices, std::size_t count, double y0, double y1, double& x_min, double& x_max) {
  x_min = std::numeric_limits<double>::infinity();
  x_max = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < count; ++i) {
    const Vec2& a = vertices[i];
    if (a.y() >= y0 && a.y() <= y1) {
      x_min = std::min(x_min, a.x());
      x_max = std::max(x_max, a.x());
    }
    const Vec2& b = vertices[(i + 1) % count];
    if (a.y() == b.y()) continue;
    for (const double yl : {y0, y1}) {
      if ((a.y() - yl) * (b.y() - yl) > 0.0) continue;
      const double x = a.x() + (yl - a.y()) / (b.y() - a.y()) * (b.x() - a.x());
      x_min = std::min(x_min, x);
      x_max = std::max(x_max, x);
    }
  }
  return x_min <= x_max;
}

Costmap::Costmap(const Pose2& origin, double resolution, int width, int height, std::vector<std::uint8_t> occupied,
                 const StopCondition& stop)
    : Costmap(origin, resolution, width, height, std::move(occupied), kDeferred) {
  precompute(stop);
}

Costmap::Costmap(const Pose2& origin, double resolution, int width, int height, std::vector<std::uint8_t> occupied,
                 Deferred /*unused*/)
    : origin_(origin),
      resolution_(resolution),
      cos_(std::cos(origin.yaw)),
      sin_(std::sin(origin.yaw)),
      width_(std::max(0, width)),
      height_(std::max(0, height)),
      occupied_(std::move(occupied)) {
  occupied_.resize(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_), 0);
}

Costmap Costmap::from_occupancy_grid(const OccupancyGrid& grid, int obstacle_threshold, const StopCondition& stop) {
  if (const StopReason reason = stop.check(); reason != StopReason::kNone) {  // before allocating anything
    Costmap map(grid.origin, grid.resolution_m, 0, 0, {}, kDeferred);
    map.stopped_ = reason;
    return map;
  }
  std::vector<std::uint8_t> occ(grid.data.size());
  for (std::size_t i = 0; i < grid.data.size(); ++i) {
    occ[i] = (grid.data[i] < 0 || grid.data[i] >= obstacle_threshold) ? 1 : 0;
  }
  return Costmap(grid.origin, grid.resolution_m, static_cast<int>(grid.width), static_cast<int>(grid.height),
                 std::move(occ), stop);
}

Costmap Costmap::from_polygons(const Aabb& extent, double resolution, const std::vector<Polygon>& drivable,
                               const std::vector<std::pair<Vec2, Vec2>>& drivable_outline,
                               const std::vector<Polygon>& obstacles, const StopCondition& stop) {
  const int w = clamped_int(std::ceil((extent.max.x() - extent.min.x()) / resolution), 1, kMaxSideCells);
  const int h = clamped_int(std::ceil((extent.max.y() - extent.min.y()) / resolution), 1, kMaxSideCells);
  const Pose2 origin{extent.min.x(), extent.min.y(), 0.0};
  StopReason stopped = StopReason::kNone;
  const auto stopped_map = [&]() {
    Costmap map(origin, resolution, 0, 0, {}, kDeferred);
    map.stopped_ = stopped;
    return map;
  };
  if ((stopped = stop.check()) != StopReason::kNone) return stopped_map();  // before allocating anything
  std::vector<std::uint8_t> occ(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), 1);

  // Cells whose centre lies inside some drivable polygon (even-odd rule per polygon, the union
  // over polygons), found by one crossing list per row at the cell centres' height.
  std::vector<std::vector<double>> crossings(static_cast<std::size_t>(h));
  for (const Polygon& poly : drivable) {
    if ((stopped = stop.check()) != StopReason::kNone) return stopped_map();
    for (auto& row : crossings) row.clear();
    for (std::size_t i = 0; i < poly.size(); ++i) {
      const Vec2 a = (poly[i] - extent.min) / resolution;
      const Vec2 b = (poly[(i + 1) % poly.size()] - extent.min) / resolution;
      if (a.y() == b.y()) continue;
      const double lo = std::min(a.y(), b.y());
      const double hi = std::max(a.y(), b.y());
      // Rows j whose centre j + 0.5 is in [lo, hi): half-open, so a vertex is counted once.
      const int j0 = clamped_int(std::ceil(lo - 0.5), 0, h);
      const int j1 = clamped_int(std::ceil(hi - 0.5) - 1.0, -1, h - 1);
      for (int j = j0; j <= j1; ++j) {
        const double y = j + 0.5;
        crossings[static_cast<std::size_t>(j)].push_back(a.x() + (y - a.y()) / (b.y() - a.y()) * (b.x() - a.x()));
      }
    }
    for (int j = 0; j < h; ++j) {
      if (stop_now(stop, j, stopped)) return stopped_map();
      auto& xs = crossings[static_cast<std::size_t>(j)];
      std::sort(xs.begin(), xs.end());
      for (std::size_t k = 0; k + 1 < xs.size(); k += 2) {
        // Columns whose centre i + 0.5 lies in [xs[k], xs[k+1]].
        const int i0 = clamped_int(std::ceil(xs[k] - 0.5), 0, w);
        const int i1 = clamped_int(std::floor(xs[k + 1] - 0.5), -1, w - 1);
        for (int i = i0; i <= i1; ++i) occ[static_cast<std::size_t>(j) * w + i] = 0;
      }
    }
  }
  Costmap map(origin, resolution, w, h, std::move(occ), kDeferred);
  // Cells with their centre outside the lanes and crossed by no outline edge lie entirely outside:
  // hard. The outline cuts through the cells it touches: those are partial (the edge decides).
  map.ensure_hard();
  for (const Polygon& poly : drivable) {
    std::vector<Vec2> g;
    g.reserve(poly.size());
    for (const Vec2& p : poly) g.push_back(map.to_grid(p));
    map.drivable_rows_.push_back(edge_rows(g, h));
    map.drivable_.push_back(std::move(g));
  }
  std::vector<Polygon> blocked;
  blocked.reserve(drivable_outline.size() + obstacles.size());
  for (const auto& [a, b] : drivable_outline) blocked.push_back({a, b});
  blocked.insert(blocked.end(), obstacles.begin(), obstacles.end());
  if (map.mark(blocked, stop, drivable_outline.size())) map.precompute(stop);
  return map;
}

void Costmap::add_obstacles(const std::vector<Polygon>& polygons, const StopCondition& stop) {
  ensure_hard();
  if (mark(polygons, stop)) precompute(stop);
}

void Costmap::ensure_hard() {
  if (hard_.size() != occupied_.size()) hard_ = occupied_;
}

void Costmap::partial_shapes(int ix, int iy, std::vector<std::uint32_t>& out) const {
  const auto cell = static_cast<std::uint32_t>(index(ix, iy));
  auto it = std::lower_bound(partial_.begin(), partial_.end(), std::make_pair(cell, std::uint32_t{0}));
  for (; it != partial_.end() && it->first == cell; ++it) out.push_back(it->second);
}

void Costmap::partial_shapes_in_row(int c0, int c1, int iy, std::vector<std::uint32_t>& out) const {
  const auto first = static_cast<std::uint32_t>(index(c0, iy));
  const auto last = static_cast<std::uint32_t>(index(c1, iy));
  auto it = std::lower_bound(partial_.begin(), partial_.end(), std::make_pair(first, std::uint32_t{0}));
  // The list is sorted by cell: its entries for the row's cells follow one another. Only occupied
  // cells count, as for the callers of partial_shapes. A shape usually covers several neighbouring
  // cells: an id equal to the last one appended is left out (the callers want the set).
  for (; it != partial_.end() && it->first <= last; ++it) {
    if (occupied_[it->first] != 0 && (out.empty() || out.back() != it->second)) out.push_back(it->second);
  }
}

bool Costmap::inside_drivable(const Vec2& p_G) const {
  if (drivable_.empty()) return true;
  const double y = p_G.y();
  if (!(y >= 0.0 && y < static_cast<double>(height_))) {
    return std::any_of(drivable_.begin(), drivable_.end(),
                       [&](const std::vector<Vec2>& poly) { return poly.size() >= 3 && point_in_polygon(poly, p_G); });
  }
  // point_in_polygon's even-odd count over the edges that can cross the height y (the others do
  // not change it), with its arithmetic: the same answer.
  const auto row = static_cast<std::size_t>(y);
  for (std::size_t k = 0; k < drivable_.size(); ++k) {
    const std::vector<Vec2>& poly = drivable_[k];
    if (poly.size() < 3) continue;
    const EdgeRows& rows = drivable_rows_[k];
    bool inside = false;
    for (std::uint32_t e = rows.row_start[row]; e < rows.row_start[row + 1]; ++e) {
      const std::uint32_t i = rows.edges[e];
      const Vec2& a = poly[i];
      const Vec2& b = poly[i == 0 ? poly.size() - 1 : i - 1];
      if ((a.y() > y) != (b.y() > y)) {
        const double x_cross = a.x() + (y - a.y()) * (b.x() - a.x()) / (b.y() - a.y());
        if (p_G.x() < x_cross) inside = !inside;
      }
    }
    if (inside) return true;
  }
  return false;
}

Costmap::EdgeRows Costmap::edge_rows(const std::vector<Vec2>& poly, int height) {
  EdgeRows out;
  const auto rows = static_cast<std::size_t>(std::max(0, height));
  // Rows floor(min y) .. floor(max y) (clamped to the grid) hold the edge: every height y in a row
  // r with min y <= y < max y, the edge's crossing condition, has floor(min y) <= r <= floor(max y).
  // A non-finite coordinate puts the edge in every row.
  const auto span = [&](std::size_t i, std::size_t& r0, std::size_t& r1) {
    const Vec2& a = poly[i];
    const Vec2& b = poly[i == 0 ? poly.size() - 1 : i - 1];
    const double lo = std::min(a.y(), b.y());
    const double hi = std::max(a.y(), b.y());
    if (!std::isfinite(lo) || !std::isfinite(hi)) {
      r0 = 0;
      r1 = rows - 1;
      return;
    }
    r0 = static_cast<std::size_t>(clamped_int(std::floor(lo), 0, height - 1));
    r1 = static_cast<std::size_t>(clamped_int(std::floor(hi), 0, height - 1));
  };
  out.row_start.assign(rows + 1, 0);
  if (rows == 0) return out;
  std::size_t r0 = 0;
  std::size_t r1 = 0;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    span(i, r0, r1);
    for (std::size_t r = r0; r <= r1; ++r) ++out.row_start[r + 1];
  }
  for (std::size_t r = 0; r < rows; ++r) out.row_start[r + 1] += out.row_start[r];
  out.edges.resize(out.row_start[rows]);
  std::vector<std::uint32_t> fill(out.row_start.begin(), out.row_start.end() - 1);
  for (std::size_t i = 0; i < poly.size(); ++i) {
    span(i, r0, r1);
    for (std::size_t r = r0; r <= r1; ++r) out.edges[fill[r]++] = static_cast<std::uint32_t>(i);
  }
  return out;
}

bool Costmap::mark(const std::vector<Polygon>& polygons, const StopCondition& stop, std::size_t lane_edges) {
  std::vector<Vec2> g;
  std::vector<std::uint32_t> edge_cells;
  std::vector<double> crossings;
  std::size_t count = 0;
  for (const Polygon& poly : polygons) {
    if (poly.empty()) continue;
    if (stop_now(stop, static_cast<int>(count++ % kStopCheckRows), stopped_)) return false;
    g.clear();
    double y_lo = std::numeric_limits<double>::infinity();
    double y_hi = -y_lo;
    for (const Vec2& p : poly) {
      g.push_back(to_grid(p));
      y_lo = std::min(y_lo, g.back().y());
      y_hi = std::max(y_hi, g.back().y());
    }
    // A cell is marked when the polygon meets its interior: a polygon that ends exactly on a
    // cell boundary (a wall 0.4 m thick on 0.2 m cells) does not mark the next cell.
    constexpr double kInterior = 1e-9;  // [cells]
    // The cells of the convex hull of pts (at most the whole polygon's row extents), calling
    // visit(i, j) for each.
    const auto cells_of = [&](const Vec2* pts, std::size_t n, auto&& visit) {
      double lo = std::numeric_limits<double>::infinity();
      double hi = -lo;
      for (std::size_t k = 0; k < n; ++k) {
        lo = std::min(lo, pts[k].y());
        hi = std::max(hi, pts[k].y());
      }
      const int j0 = clamped_int(std::floor(lo + kInterior), 0, height_);
      const int j1 = clamped_int(std::floor(hi - kInterior), -1, height_ - 1);
      for (int j = j0; j <= j1; ++j) {
        double x0 = 0.0;
        double x1 = 0.0;
        if (!strip_extent(pts, n, j + kInterior, j + 1.0 - kInterior, x0, x1)) continue;
        const int i0 = clamped_int(std::floor(x0 + kInterior), 0, width_);
        const int i1 = clamped_int(std::floor(x1 - kInterior), -1, width_ - 1);
        for (int i = i0; i <= i1; ++i) visit(i, j);
      }
    };
    // The exact layer: the cells an edge meets are partial, the others hard when their centre lies
    // inside the polygon (the row extents of a non-convex polygon also cover its concavities:
    // those cells are partial, the exact test finds them free).
    const auto shape = static_cast<std::uint32_t>(shapes_.size());
    shapes_.push_back({g, g.size() >= 3});
    edge_cells.clear();
    for (std::size_t k = 0; k < g.size(); ++k) {
      if (!shapes_.back().closed && k + 1 == g.size() && g.size() > 1) break;
      const std::array<Vec2, 2> e{g[k], g[(k + 1) % g.size()]};
      cells_of(e.data(), 2, [&](int i, int j) { edge_cells.push_back(static_cast<std::uint32_t>(index(i, j))); });
    }
    std::sort(edge_cells.begin(), edge_cells.end());
    edge_cells.erase(std::unique(edge_cells.begin(), edge_cells.end()), edge_cells.end());
    const bool closed = shapes_.back().closed;
    // A lane edge decides the cells it crosses (their part outside the lanes is found by
    // inside_drivable), so those are partial even where the centre lies outside.
    const bool lane_edge = static_cast<std::size_t>(&poly - polygons.data()) < lane_edges;
    if (lane_edge) {
      cells_of(g.data(), g.size(), [&](int i, int j) {
        const std::size_t c = index(i, j);
        occupied_[c] = 1;
        hard_[c] = 0;
        partial_.emplace_back(static_cast<std::uint32_t>(c), shape);
      });
      continue;
    }
    // The cells an edge meets: partial (the exact test decides), unless already hard.
    for (const std::uint32_t c : edge_cells) {
      occupied_[c] = 1;
      if (hard_[c] == 0) partial_.emplace_back(c, shape);
    }
    if (!closed) continue;
    // Every other cell lies entirely inside the polygon or entirely outside it: hard when its
    // centre is inside. Per row, the crossings of the edges with the centres' height, with
    // point_in_polygon's rule and arithmetic (so each centre gets exactly its answer): a centre is
    // inside when an odd number of crossings lie to its right.
    const int r0 = clamped_int(std::floor(y_lo), 0, height_);
    const int r1 = clamped_int(std::floor(y_hi), -1, height_ - 1);
    auto edge_it = edge_cells.begin();
    for (int j = r0; j <= r1; ++j) {
      // One polygon may cover the whole grid (max_grid_cells): checked every 64 of its rows too.
      if (j > r0 && stop_now(stop, j - r0, stopped_)) return false;
      const double y = j + 0.5;
      crossings.clear();
      for (std::size_t k = 0, m = g.size() - 1; k < g.size(); m = k++) {
        const Vec2& a = g[k];
        const Vec2& b = g[m];
        if ((a.y() > y) != (b.y() > y)) crossings.push_back(a.x() + (y - a.y()) * (b.x() - a.x()) / (b.y() - a.y()));
      }
      std::sort(crossings.begin(), crossings.end());
      const auto row_begin = static_cast<std::uint32_t>(index(0, j));
      while (edge_it != edge_cells.end() && *edge_it < row_begin) ++edge_it;
      // Centres x in [crossings[k], crossings[k + 1]) for even k have an odd count to their right.
      for (std::size_t k = 0; k + 1 < crossings.size(); k += 2) {
        int i = clamped_int(std::ceil(crossings[k] - 0.5), 0, width_);
        while (i > 0 && (i - 1) + 0.5 >= crossings[k]) --i;  // exact: the first centre at or right of it
        while (i < width_ && i + 0.5 < crossings[k]) ++i;
        for (; i < width_ && i + 0.5 < crossings[k + 1]; ++i) {
          const auto c = static_cast<std::uint32_t>(index(i, j));
          while (edge_it != edge_cells.end() && *edge_it < c) ++edge_it;
          if (edge_it != edge_cells.end() && *edge_it == c) continue;  // an edge meets it: partial
          occupied_[c] = 1;
          hard_[c] = 1;
        }
      }
    }
  }
  return true;
}

Vec2 Costmap::to_grid(const Vec2& p) const {
  const double dx = p.x() - origin_.x;
  const double dy = p.y() - origin_.y;
  return {(cos_ * dx + sin_ * dy) / resolution_, (-sin_ * dx + cos_ * dy) / resolution_};
}

Vec2 Costmap::to_map(const Vec2& g) const {
  const double x = g.x() * resolution_;
  const double y = g.y() * resolution_;
  return {origin_.x + cos_ * x - sin_ * y, origin_.y + sin_ * x + cos_ * y};
}

void Costmap::cell_of(const Vec2& p_M, int& ix, int& iy) const {
  const Vec2 g = to_grid(p_M);
  // Clamped before the conversion so that far-away points cannot overflow int.
  ix = clamped_int(std::floor(g.x()), -2, width_ + 2);
  iy = clamped_int(std::floor(g.y()), -2, height_ + 2);
}

double Costmap::clearance_lower_bound(const Vec2& p_M) const {
  int ix = 0;
  int iy = 0;
  cell_of(p_M, ix, iy);
  if (occupied(ix, iy)) return 0.0;
  // p is within res/sqrt2 of its cell centre, and an occupied square within res/sqrt2 of its own.
  return std::max(0.0, centre_distance(ix, iy) - kSqrt2 * resolution_);
}

int Costmap::occupied_in_row(int iy, int c0, int c1) const { return static_cast<int>(occupied_in_box(c0, iy, c1, iy)); }

long long Costmap::occupied_in_box(int c0, int r0, int c1, int r1) const {
  if (c1 < c0 || r1 < r0) return 0;
  const long long area = (static_cast<long long>(c1) - c0 + 1) * (static_cast<long long>(r1) - r0 + 1);
  const int ic0 = std::max(c0, 0);
  const int ir0 = std::max(r0, 0);
  const int ic1 = std::min(c1, width_ - 1);
  const int ir1 = std::min(r1, height_ - 1);
  if (ic1 < ic0 || ir1 < ir0) return area;  // entirely outside
  const long long inside = (static_cast<long long>(ic1) - ic0 + 1) * (static_cast<long long>(ir1) - ir0 + 1);
  return area - inside + occupied_in_box_inside(ic0, ir0, ic1, ir1);
}

void Costmap::precompute(const StopCondition& stop) {
  box_ = BoxCounts();
  hard_box_ = BoxCounts();
  distance_ = DistanceField();
  if (!partial_.empty()) {
    // The list holds up to 64 edges x (width + height) entries per polygon: tens of millions.
    if (const StopReason reason = stop.check(); reason != StopReason::kNone) {
      stopped_ = reason;
      return;
    }
    std::sort(partial_.begin(), partial_.end());
    partial_.erase(std::unique(partial_.begin(), partial_.end()), partial_.end());
    // A cell made hard by a later shape needs no exact test.
    partial_.erase(std::remove_if(partial_.begin(), partial_.end(), [&](const auto& e) { return hard_[e.first] != 0; }),
                   partial_.end());
  }
  if (empty()) return;
  StopReason reason = StopReason::kNone;
  if (!partial_.empty()) reason = hard_box_.build(hard_.data(), width_, height_, stop);
  if (reason == StopReason::kNone) reason = box_.build(occupied_.data(), width_, height_, stop);
  if (reason == StopReason::kNone) reason = distance_.build(occupied_.data(), width_, height_, resolution_, stop);
  if (reason != StopReason::kNone) stopped_ = reason;
}

}  // namespace pullout
