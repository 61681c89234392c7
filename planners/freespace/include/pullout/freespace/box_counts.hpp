// Counts of the non-zero cells of a grid in axis-aligned boxes, O(1) per box: a summed-area table
// (Crow, "Summed-area tables for texture mapping", SIGGRAPH 1984) filled per band of kBandRows
// table rows on first use. build() leaves each band's first row (one read-only sweep of the grid);
// a band is filled from it and its own grid rows. A search that stays in one part of a large map
// writes (and touches the pages of) that part of the table only.
//
// The table keeps no pointer to the grid: the calls that may fill take it again (the owner may
// move or copy it).
//
// Thread safety: const methods may be called concurrently (FillFlags). A copy shares nothing.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "pullout/freespace/lazy_fill.hpp"
#include "pullout/search/stop_condition.hpp"

namespace pullout {

class BoxCounts {
 public:
  static constexpr int kBandShift = 6;
  static constexpr int kBandRows = 1 << kBandShift;

  BoxCounts() = default;
  BoxCounts(const BoxCounts& other);
  BoxCounts& operator=(const BoxCounts& other);
  BoxCounts(BoxCounts&& other) noexcept = default;
  BoxCounts& operator=(BoxCounts&& other) noexcept = default;
  ~BoxCounts() = default;

  // Prepares the counts of `cells` (row-major, width x height, non-zero counts; width, height > 0
  // and width x height < 2^31). Checks `stop` every 64 rows: kNone when complete, else the reason
  // it gave (then empty()).
  StopReason build(const std::uint8_t* cells, int width, int height, const StopCondition& stop = {});

  bool empty() const { return width_ == 0; }

  // Non-zero cells in columns c0..c1 and rows r0..r1 (0 <= c0 <= c1 < width, 0 <= r0 <= r1 <
  // height). `cells` is the grid given to build() (unchanged since).
  int count(int c0, int r0, int c1, int r1, const std::uint8_t* cells) const {
    const std::int32_t* lo = row(r0, cells);
    const std::int32_t* hi = row(r1 + 1, cells);
    return hi[c1 + 1] - hi[c0] - lo[c1 + 1] + lo[c0];
  }

  // count(c0, r, c1, r): one row, whose two table rows are neighbours in memory and usually in
  // one band (then one readiness check).
  int count_row(int c0, int c1, int r, const std::uint8_t* cells) const {
    const std::int32_t* lo = row(r, cells);
    const std::int32_t* hi = ((r + 1) >> kBandShift) == (r >> kBandShift) ? lo + stride_ : row(r + 1, cells);
    return hi[c1 + 1] - hi[c0] - lo[c1 + 1] + lo[c0];
  }

  std::size_t filled_bands() const { return bands_.count_ready(); }

 private:
  // Table row r (0..height): the non-zero cells in rows < r, per column prefix (width + 1 entries).
  const std::int32_t* row(int r, const std::uint8_t* cells) const {
    const auto band = static_cast<std::size_t>(r >> kBandShift);
    if (!bands_.ready(band)) fill(band, cells);
    return table_.data() + static_cast<std::size_t>(r) * stride_;
  }
  void fill(std::size_t band, const std::uint8_t* cells) const;

  int width_{0};
  int height_{0};
  std::size_t stride_{0};                            // width + 1
  std::vector<std::int32_t> first_;                  // per band: its first table row (row band * kBandRows)
  mutable UninitialisedVector<std::int32_t> table_;  // (height + 1) x stride, valid where the band is ready
  FillFlags bands_;
};

}  // namespace pullout
