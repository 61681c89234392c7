// The Euclidean distance transform of a binary grid, computed where it is asked for.
//
// The distance of a cell is the one from its centre to the centre of the nearest occupied cell,
// the cells one beyond the grid's border counting as occupied. It is exact: the same numbers as
// the full two-pass transform (Felzenszwalb & Huttenlocher, "Distance Transforms of Sampled
// Functions", Theory of Computing 8, 2012), which the costmap used to compute for every cell up
// front (about 30 ms for 1000 x 1000 cells, more than most searches on it).
//
// Both passes run on first use instead:
//  - the first (per column, the distance g to the nearest occupied cell of that column) per band of
//    kBandRows rows, the whole width: build() leaves at every band's edges the distance to the
//    nearest occupied cell beyond it (one read-only sweep of the grid up and one down), so a band
//    is filled from its own rows;
//  - the second (along a row: the lower envelope of the parabolas (x - k)^2 + g(k)^2 of its
//    columns k) per segment of kSegmentCells cells of a row. A cell's nearest occupied cell lies no
//    farther than its own column's g (nor than the border), so only the columns within the
//    segment's largest such bound take part: a segment costs O(kSegmentCells + that bound).
// A search that stays in one part of a large map pays for that part (and the two sweeps) only.
//
// The field keeps no pointer to the grid: the calls that may fill take it again (the owner may
// move or copy it, as Costmap does).
//
// Thread safety: const methods may be called concurrently (each band and segment is filled once,
// FillFlags). A copy shares nothing with the original.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "pullout/freespace/lazy_fill.hpp"
#include "pullout/search/stop_condition.hpp"

namespace pullout {

class DistanceField {
 public:
  static constexpr int kBandShift = 6;
  static constexpr int kBandRows = 1 << kBandShift;  // rows of the first pass filled together
  static constexpr int kSegmentShift = 6;
  static constexpr int kSegmentCells = 1 << kSegmentShift;  // cells of a row of the second pass filled together

  DistanceField() = default;
  DistanceField(const DistanceField& other);
  DistanceField& operator=(const DistanceField& other);
  DistanceField(DistanceField&& other) noexcept = default;
  DistanceField& operator=(DistanceField&& other) noexcept = default;
  ~DistanceField() = default;

  // Prepares the field of `occupied` (row-major, width x height, non-zero = occupied; width and
  // height > 0, width x height < 2^31), cells of `resolution` [m]: O(cells) reads, O(width x height / kBandRows)
  // writes. Checks `stop` every 64 rows: kNone when complete, else the reason it gave (the field is then empty and must
  // not be read).
  StopReason build(const std::uint8_t* occupied, int width, int height, double resolution,
                   const StopCondition& stop = {});

  bool empty() const { return width_ == 0; }
  int width() const { return width_; }
  int height() const { return height_; }

  // Distance [m] from the centre of cell (ix, iy) (inside the grid) to the centre of the nearest
  // occupied cell: sqrt(squared distance in cells) * resolution, rounded to float. `occupied` is
  // the grid given to build() (unchanged since).
  float at(int ix, int iy, const std::uint8_t* occupied) const {
    const std::size_t segment = static_cast<std::size_t>(iy) * static_cast<std::size_t>(segments_per_row_) +
                                (static_cast<std::size_t>(ix) >> kSegmentShift);
    if (!segments_.ready(segment)) fill(ix, iy, segment, occupied);
    return distance_[index(ix, iy)];
  }

  // The squared distances [cells^2] of cells x0 .. x1 - 1 of row iy (inside the grid,
  // 0 < x1 - x0 <= kMaxCappedCells) into out[0 .. x1 - x0), capped: exact where the squared
  // distance is below (cap + 1)^2, at least (cap + 1)^2 where it is not (1 <= cap <= kMaxCap).
  // Fills the row's band of the first pass if needed, never the second pass: each cell is the
  // least of dx^2 + g(x + dx)^2 over |dx| <= cap (g: the first pass, taken at most cap + 1), a
  // brute force whose loops vectorise (16-bit lanes), several times cheaper per cell than the
  // lower envelope while the cap is a few tens of cells. For callers that need distances only up
  // to a bound (the obstacle heuristic's room to turn).
  static constexpr int kMaxCap = 126;  // (cap + 1)^2 + cap^2 fits in int16
  static constexpr int kMaxCappedCells = 256;
  static_assert(kSegmentCells <= kMaxCappedCells, "row_segment's brute force takes a whole segment");
  // The second pass of a segment whose cells all lie at most this many cells from an occupied
  // one is the same brute force, capped there (exact), instead of the lower envelope.
  static constexpr int kBruteForceReach = 48;
  void capped_squared(int iy, int x0, int x1, int cap, std::int16_t* out, const std::uint8_t* occupied) const;

  // How much of the two passes ran so far (for tests and benchmarks).
  std::size_t filled_bands() const { return bands_.count_ready(); }
  std::size_t filled_segments() const { return segments_.count_ready(); }

 private:
  std::size_t index(int ix, int iy) const {
    return static_cast<std::size_t>(iy) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(ix);
  }
  void fill(int ix, int iy, std::size_t segment, const std::uint8_t* occupied) const;
  void fill_band(int band, const std::uint8_t* occupied) const;
  // The second pass for cells x0..x1 - 1 of row iy (its band filled) into out[0 .. x1 - x0).
  void row_segment(int iy, int x0, int x1, float* out) const;

  int width_{0};
  int height_{0};
  double resolution_{1.0};
  int segments_per_row_{0};
  // Per band b and column i: the distance from row b * kBandRows - 1 to the nearest occupied cell
  // of column i at or below it (row -1 occupied), and from row (b + 1) * kBandRows (or height) to
  // the nearest one at or above it (row height occupied).
  std::vector<std::uint32_t> below_;
  std::vector<std::uint32_t> above_;
  // First pass per cell (valid where its band is ready), saturated at kMaxColumn: exact all the
  // same. A column distance is at most (height + 1) / 2; it saturates only when the height
  // exceeds 131068, so (width x height < 2^31) the width is below 16385 and every distance below
  // 8193: a saturated column's parabola stays above the envelope.
  // Second pass [m] per cell (valid where its segment is ready). Allocated uninitialised: the
  // pages nobody asks for are never touched.
  static constexpr std::uint32_t kMaxColumn = 65535;
  mutable UninitialisedVector<std::uint16_t> column_;
  mutable UninitialisedVector<float> distance_;
  FillFlags bands_;
  FillFlags segments_;
};

}  // namespace pullout
