// A spatial hash index over a uniform square grid (cells of grid_cell.hpp): values filed under the
// cells their bounding box covers. Used by the lanes (LaneWorld) and the Lanelet2 map (LaneletMap).
//
// It only proposes candidates: a query calls back with every value filed under a cell it touches
// (a value covering several of those cells once per cell) and every wide value, and the caller
// makes the exact test. A value whose box covers more than `max_cells_per_value` cells (a long
// diagonal, far-apart points) is kept in a "wide" list tested on every query instead, so that the
// index costs what it holds, not what its coordinates span.
//
// Filled once, then immutable: the const queries may run concurrently.
#pragma once

#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "pullout/geometry/grid_cell.hpp"
#include "pullout/geometry/polygon.hpp"

namespace pullout {

template <typename T>
class GridIndex {
 public:
  // cell_size > 0 [m].
  explicit GridIndex(double cell_size, double max_cells_per_value = 4096)
      : cell_size_(cell_size), max_cells_per_value_(max_cells_per_value) {}

  double cell_size() const { return cell_size_; }
  // Cells holding at least one value.
  std::size_t occupied_cells() const { return cells_.size(); }

  // How many cells `box` covers, in double: the clamped indices span up to 2^31 cells each way.
  double cell_count(const Aabb& box) const {
    const auto span = [this](double lo, double hi) {
      return static_cast<double>(cell_index(hi, cell_size_) - cell_index(lo, cell_size_) + 1);
    };
    return span(box.min.x(), box.max.x()) * span(box.min.y(), box.max.y());
  }

  // Files `value` under every cell `box` covers (or in the wide list, see above).
  void insert(const Aabb& box, const T& value) {
    if (cell_count(box) > max_cells_per_value_) {
      wide_.push_back(value);
      return;
    }
    for_cells(box, [&](std::uint64_t key) { cells_[key].push_back(value); });
  }

  // Calls visit(value) for the values of the cell containing p and the wide values until it
  // returns true; returns whether it did.
  template <typename F>
  bool any_at(const Vec2& p, F&& visit) const {
    const auto it = cells_.find(cell_key(cell_index(p.x(), cell_size_), cell_index(p.y(), cell_size_)));
    if (it != cells_.end()) {
      for (const T& v : it->second) {
        if (visit(v)) return true;
      }
    }
    return any_wide(visit);
  }

  // Calls visit(value) for the values of every cell `box` covers (once per cell) and the wide
  // values until it returns true; returns whether it did.
  template <typename F>
  bool any_in(const Aabb& box, F&& visit) const {
    bool found = false;
    for_cells(box, [&](std::uint64_t key) {
      if (found) return;
      const auto it = cells_.find(key);
      if (it == cells_.end()) return;
      for (const T& v : it->second) {
        if (visit(v)) {
          found = true;
          return;
        }
      }
    });
    return found || any_wide(visit);
  }

 private:
  template <typename F>
  void for_cells(const Aabb& box, F&& f) const {
    const std::int64_t x0 = cell_index(box.min.x(), cell_size_);
    const std::int64_t x1 = cell_index(box.max.x(), cell_size_);
    const std::int64_t y0 = cell_index(box.min.y(), cell_size_);
    const std::int64_t y1 = cell_index(box.max.y(), cell_size_);
    for (std::int64_t ix = x0; ix <= x1; ++ix) {
      for (std::int64_t iy = y0; iy <= y1; ++iy) f(cell_key(ix, iy));
    }
  }

  template <typename F>
  bool any_wide(F&& visit) const {
    for (const T& v : wide_) {
      if (visit(v)) return true;
    }
    return false;
  }

  double cell_size_;
  double max_cells_per_value_;
  std::unordered_map<std::uint64_t, std::vector<T>> cells_;
  std::vector<T> wide_;
};

}  // namespace pullout
