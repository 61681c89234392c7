// The costmap of the freespace planner: a binary occupancy grid with what the search needs
// precomputed (a summed-area table for exact footprint tests, a Euclidean distance transform for
// cheap clearance bounds).
//
// Frames: the grid frame G has its origin at the outer corner of cell (0, 0) and its axes along
// the rows (+x, increasing column) and columns (+y, increasing row); X_MG = `origin` is its pose in
// the map frame M (ROS nav_msgs/OccupancyGrid convention, row-major from the origin). Cell (i, j)
// (column i, row j) is the closed square [i, i+1] x [j, j+1] in cell units (x resolution in
// metres). Everything outside the grid counts as occupied: the planner never leaves the map.
//
// Sources:
//  - a request's occupancy grid (ROS values 0..100, -1 unknown): a cell is an obstacle when its
//    value is unknown (< 0) or >= obstacle_threshold, as in Autoware's costmap_configs;
//  - the drivable area (lane polygons) and static object footprints, rasterised conservatively: a
//    cell is free only when it lies entirely inside the lanes and touches no object.
//
// Exact shapes: the polygons and lane edges rasterised here are kept (grid frame). Every occupied
// cell is then either hard (entirely covered: outside the lanes and crossed by no lane edge, inside
// an object and crossed by none of its edges, or a cell of a request's occupancy grid) or partial
// (only partly covered: the shapes that meet it are listed). occupied() stays conservative; the
// collision checker tests partial cells against the listed shapes exactly (partial_shapes,
// hard_in_box_inside, inside_drivable). A grid from a request has no shapes: all its cells are hard.
//
// The distance transform is exact for cell centres. It and the summed-area tables are computed
// lazily (DistanceField, BoxCounts): building leaves one read-only sweep of the grid per table;
// the rest is filled per band of rows or row segment where the search first asks, so a search
// that stays in one part of a large map pays for that part.
//
// Building costs O(cells) (up to 16384 x 16384 from polygons, max_grid_cells from a grid) and
// honours a stop condition: it is checked before every drivable polygon, every 64 rows of the
// rasterisation, every 64 obstacle polygons and every 64 rows of one, before the exact layer's
// list is sorted, and every 64 rows of the tables' sweeps. A build it cuts short returns at once
// with stopped() set; such a costmap is incomplete and must not be searched. The fills on first use take no stop
// condition: each is bounded (a band of 64 rows, a row segment).
#pragma once

#include <cstdint>
#include <vector>

#include "pullout/freespace/box_counts.hpp"
#include "pullout/freespace/distance_field.hpp"
#include "pullout/geometry/polygon.hpp"
#include "pullout/model/types.hpp"
#include "pullout/search/stop_condition.hpp"

namespace pullout {

class Costmap {
 public:
  Costmap() = default;
  // `occupied` is row-major (width x height), non-zero = obstacle. resolution > 0 [m].
  Costmap(const Pose2& origin, double resolution, int width, int height, std::vector<std::uint8_t> occupied,
          const StopCondition& stop = {});

  // From a ROS occupancy grid: unknown (< 0) or >= obstacle_threshold is an obstacle.
  static Costmap from_occupancy_grid(const OccupancyGrid& grid, int obstacle_threshold, const StopCondition& stop = {});
  // An axis-aligned grid over `extent` (map frame) at `resolution`: free where a cell lies inside
  // the union of `drivable` polygons (simple polygons, any orientation) and touches no `obstacles`
  // polygon. `drivable_outline` lists the edges of the union's outline (edges shared by two lanes
  // excluded); cells it touches are obstacles. At most 16384 cells a side: a larger extent is cut
  // at its max corner (what is cut off lies outside the grid, so counts as occupied).
  static Costmap from_polygons(const Aabb& extent, double resolution, const std::vector<Polygon>& drivable,
                               const std::vector<std::pair<Vec2, Vec2>>& drivable_outline,
                               const std::vector<Polygon>& obstacles, const StopCondition& stop = {});

  // Marks every cell whose interior a polygon (map frame) meets as occupied (a segment marks the
  // cells it passes through; a cell in a non-convex polygon's concavity that no edge meets stays
  // as it was). The polygons join the exact layer. Updates the precomputation.
  void add_obstacles(const std::vector<Polygon>& polygons, const StopCondition& stop = {});

  // A polygon or lane edge kept for the exact test, grid frame in cell units. `closed`: a polygon
  // (its interior counts); otherwise a polyline (a lane edge segment, two points).
  struct Shape {
    std::vector<Vec2> points;
    bool closed{true};
  };
  // True when some occupied cell is partial (the exact layer is in use).
  bool has_partial() const { return !partial_.empty(); }
  // Hard (entirely covered) cells in the box, as occupied_in_box_inside.
  int hard_in_box_inside(int c0, int r0, int c1, int r1) const {
    if (hard_box_.empty()) return occupied_in_box_inside(c0, r0, c1, r1);
    return hard_box_.count(c0, r0, c1, r1, hard_.data());
  }
  // The same for columns c0..c1 of row r alone (0 <= c0 <= c1 < width, 0 <= r < height).
  int hard_in_row_inside(int c0, int c1, int r) const {
    if (hard_box_.empty()) return occupied_in_row_inside(c0, c1, r);
    return hard_box_.count_row(c0, c1, r, hard_.data());
  }
  // Appends the indices (into shapes()) of the shapes meeting partial cell (ix, iy) in the grid.
  void partial_shapes(int ix, int iy, std::vector<std::uint32_t>& out) const;
  // The same for the occupied cells c0..c1 of row iy (inside the grid), in column order: what
  // partial_shapes would append cell by cell, with one search of the list instead of one per cell,
  // less the ids equal to the one appended just before (the same set, fewer repeats).
  void partial_shapes_in_row(int c0, int c1, int iy, std::vector<std::uint32_t>& out) const;
  const std::vector<Shape>& shapes() const { return shapes_; }
  // Whether grid point p (cell units) lies inside the drivable polygons (always true for a costmap
  // without drivable polygons). Even-odd per polygon, union over polygons.
  bool inside_drivable(const Vec2& p_G) const;

  // Why the last build step was cut short (see the file comment); kNone when complete.
  StopReason stopped() const { return stopped_; }

  bool empty() const { return width_ == 0 || height_ == 0; }
  int width() const { return width_; }
  int height() const { return height_; }
  double resolution() const { return resolution_; }
  const Pose2& origin() const { return origin_; }

  // Cell occupancy; outside the grid is occupied.
  bool occupied(int ix, int iy) const {
    return ix < 0 || iy < 0 || ix >= width_ || iy >= height_ || occupied_[index(ix, iy)] != 0;
  }
  // Point in the map frame -> grid frame in cell units.
  Vec2 to_grid(const Vec2& p_M) const;
  // Grid frame in cell units -> map frame.
  Vec2 to_map(const Vec2& p_G) const;
  // The cell containing a map point (may be outside the grid).
  void cell_of(const Vec2& p_M, int& ix, int& iy) const;
  bool inside(int ix, int iy) const { return ix >= 0 && iy >= 0 && ix < width_ && iy < height_; }

  // Distance [m] from the centre of cell (ix, iy) to the centre of the nearest occupied cell
  // (inside the grid; the grid border counts as occupied, one cell beyond the edge). The first
  // call in a row segment computes that segment (see DistanceField).
  double centre_distance(int ix, int iy) const { return distance_.at(ix, iy, occupied_.data()); }
  const DistanceField& distance_field() const { return distance_; }
  // Squared centre distances [cells^2] of cells x0 .. x1 - 1 of row iy, capped at `cap` cells
  // (DistanceField::capped_squared).
  void capped_squared_distances(int iy, int x0, int x1, int cap, std::int16_t* out) const {
    distance_.capped_squared(iy, x0, x1, cap, out, occupied_.data());
  }
  // A lower bound [m] of the distance from map point p to the nearest occupied cell (as a closed
  // square); 0 outside the grid or on an occupied cell.
  double clearance_lower_bound(const Vec2& p_M) const;

  // Number of occupied cells in row iy between columns c0 and c1 (inclusive, clamped to the grid;
  // columns outside the grid count as occupied; 0 when c1 < c0).
  int occupied_in_row(int iy, int c0, int c1) const;
  // Number of occupied cells in the box of columns c0..c1 and rows r0..r1 (inclusive, clamped to
  // the grid; cells outside the grid count as occupied; 0 for an empty range). O(1): four
  // summed-area table lookups.
  long long occupied_in_box(int c0, int r0, int c1, int r1) const;
  // The same for a non-empty box inside the grid (0 <= c0 <= c1 < width, 0 <= r0 <= r1 < height),
  // without the clamping: the collision checker's hot path.
  int occupied_in_box_inside(int c0, int r0, int c1, int r1) const {
    return box_.count(c0, r0, c1, r1, occupied_.data());
  }
  // occupied_in_box_inside(c0, r, c1, r), cheaper.
  int occupied_in_row_inside(int c0, int c1, int r) const { return box_.count_row(c0, c1, r, occupied_.data()); }

 private:
  std::size_t index(int ix, int iy) const {
    return static_cast<std::size_t>(iy) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(ix);
  }
  enum Deferred { kDeferred };  // tag: the cells are set, the precomputation is left to the caller
  Costmap(const Pose2& origin, double resolution, int width, int height, std::vector<std::uint8_t> occupied, Deferred);
  // Marks the polygons' cells (add_obstacles without the precomputation); false when stopped.
  // The first `lane_edges` polygons are lane edges (see from_polygons).
  bool mark(const std::vector<Polygon>& polygons, const StopCondition& stop, std::size_t lane_edges = 0);
  // Makes the exact layer: hard_ from occupied_ (when not made yet).
  void ensure_hard();
  void precompute(const StopCondition& stop);

  Pose2 origin_;
  double resolution_{0.2};
  double cos_{1.0};
  double sin_{0.0};
  int width_{0};
  int height_{0};
  std::vector<std::uint8_t> occupied_;
  DistanceField distance_;  // [m] see centre_distance
  BoxCounts box_;           // occupied cells in boxes (a summed-area table, filled where asked)
  StopReason stopped_{StopReason::kNone};
  // The exact layer (see the file comment): hard_ per cell (empty: every occupied cell is hard),
  // its box counts, the (cell index, shape index) pairs of partial cells sorted, the shapes,
  // and the drivable polygons (grid frame).
  std::vector<std::uint8_t> hard_;
  BoxCounts hard_box_;  // empty: no exact layer
  std::vector<std::pair<std::uint32_t, std::uint32_t>> partial_;
  std::vector<Shape> shapes_;
  std::vector<std::vector<Vec2>> drivable_;
  // Per drivable polygon, per grid row: the edges (index i: from vertex i - 1 to vertex i, as
  // point_in_polygon walks them) whose y range meets that row, so that inside_drivable tests only
  // those (a bend's lanes have hundreds of edges; a row meets a few). Rows' lists in edge_rows_
  // from row_start_[r] to row_start_[r + 1] (height + 1 entries per polygon).
  struct EdgeRows {
    std::vector<std::uint32_t> row_start;
    std::vector<std::uint32_t> edges;
  };
  static EdgeRows edge_rows(const std::vector<Vec2>& poly, int height);
  std::vector<EdgeRows> drivable_rows_;
};

// The column extent of a convex polygon (grid frame, cell units) within the horizontal strip
// y in [y0, y1]: false when they do not meet. Exact (touching counts as meeting).
bool strip_extent(const Vec2* vertices, std::size_t count, double y0, double y1, double& x_min, double& x_max);

}  // namespace pullout
