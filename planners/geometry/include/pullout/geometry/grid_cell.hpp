// Cells of a uniform square grid over the plane, as used by the spatial hash indexes of the lanes
// (LaneWorld) and of the Lanelet2 map (LaneletMap).
//
// Any double maps to a cell without undefined behaviour: the cell index is floor(v / cell_size)
// clamped to [-kMaxCellIndex, kMaxCellIndex] (NaN gives -kMaxCellIndex), so points farther out
// than about 1e9 cells share the outermost cells. An index only proposes candidates for an exact
// test, so sharing a cell costs time, never a wrong answer.
#pragma once

#include <cmath>
#include <cstdint>

namespace pullout {

constexpr std::int64_t kMaxCellIndex = std::int64_t{1} << 30;

// The index of the cell containing coordinate v along one axis; cell_size > 0.
inline std::int64_t cell_index(double v, double cell_size) {
  const double c = std::floor(v / cell_size);
  if (!(c > static_cast<double>(-kMaxCellIndex))) return -kMaxCellIndex;  // also NaN
  if (c > static_cast<double>(kMaxCellIndex)) return kMaxCellIndex;
  return static_cast<std::int64_t>(c);
}

// The hash key of cell (ix, iy): the low 32 bits of each index side by side, computed unsigned
// (a left shift of a negative index would be undefined). Distinct for indices in the clamped range.
inline std::uint64_t cell_key(std::int64_t ix, std::int64_t iy) {
  return (static_cast<std::uint64_t>(ix) << 32) | (static_cast<std::uint64_t>(iy) & 0xffffffffU);
}

}  // namespace pullout
