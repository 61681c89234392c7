#include "pullout/freespace/box_counts.hpp"

#include <algorithm>

namespace pullout {

namespace {

constexpr int kStopCheckRows = 64;  // rows of build's sweep between two checks of the stop condition

}  // namespace

BoxCounts::BoxCounts(const BoxCounts& other)
    : width_(other.width_), height_(other.height_), stride_(other.stride_), first_(other.first_), bands_(other.bands_) {
  // Only the bands ready in the copied flags: the rest of other's table may never have been written.
  table_.resize(other.table_.size());
  for (std::size_t b = 0; b < bands_.size(); ++b) {
    if (!bands_.ready(b)) continue;
    const std::size_t first = b * kBandRows * stride_;
    const std::size_t last = std::min(table_.size(), first + kBandRows * stride_);
    std::copy(other.table_.begin() + static_cast<std::ptrdiff_t>(first),
              other.table_.begin() + static_cast<std::ptrdiff_t>(last),
              table_.begin() + static_cast<std::ptrdiff_t>(first));
  }
}

BoxCounts& BoxCounts::operator=(const BoxCounts& other) {
  if (this != &other) *this = BoxCounts(other);
  return *this;
}

StopReason BoxCounts::build(const std::uint8_t* cells, int width, int height, const StopCondition& stop) {
  *this = BoxCounts();
  const auto w = static_cast<std::size_t>(width);
  const std::size_t stride = w + 1;
  const int bands = height / kBandRows + 1;  // table rows 0..height
  std::vector<std::int32_t> first(static_cast<std::size_t>(bands) * stride);
  // Non-zero cells per column in the rows so far (the compiler vectorises the row loop).
  std::vector<std::int32_t> column(w, 0);
  for (int r = 0; r <= height; ++r) {
    if (r % kStopCheckRows == 0) {
      if (const StopReason reason = stop.check(); reason != StopReason::kNone) return reason;
    }
    if (r % kBandRows == 0) {
      std::int32_t* out = first.data() + static_cast<std::size_t>(r / kBandRows) * stride;
      out[0] = 0;
      for (std::size_t i = 0; i < w; ++i) out[i + 1] = out[i] + column[i];
    }
    if (r == height) break;
    const std::uint8_t* row = cells + static_cast<std::size_t>(r) * w;
    for (std::size_t i = 0; i < w; ++i) column[i] += row[i] != 0 ? 1 : 0;
  }
  width_ = width;
  height_ = height;
  stride_ = stride;
  first_ = std::move(first);
  table_.resize(stride * (static_cast<std::size_t>(height) + 1));  // uninitialised: filled per band
  bands_ = FillFlags(static_cast<std::size_t>(bands));
  return StopReason::kNone;
}

void BoxCounts::fill(std::size_t band, const std::uint8_t* cells) const {
  bands_.ensure(band, [&] {
    const auto w = static_cast<std::size_t>(width_);
    const int r0 = static_cast<int>(band) * kBandRows;
    const int r1 = std::min(height_, r0 + kBandRows - 1);  // the band's last table row
    std::int32_t* out = table_.data() + static_cast<std::size_t>(r0) * stride_;
    const std::int32_t* in = first_.data() + band * stride_;
    std::copy(in, in + stride_, out);
    for (int r = r0 + 1; r <= r1; ++r) {
      const std::int32_t* below = out;
      out += stride_;
      const std::uint8_t* row = cells + static_cast<std::size_t>(r - 1) * w;
      std::int32_t sum = 0;  // non-zero cells of grid row r - 1 left of column i + 1
      out[0] = 0;
      for (std::size_t i = 0; i < w; ++i) {
        sum += row[i] != 0 ? 1 : 0;
        out[i + 1] = below[i + 1] + sum;
      }
    }
  });
}

}  // namespace pullout
