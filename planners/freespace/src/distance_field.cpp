#include "pullout/freespace/distance_field.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace pullout {

namespace {

constexpr int kStopCheckRows = 64;  // rows of build's sweeps between two checks of the stop condition

// Copies the cells [first, last) of `from` to `to` (same size).
template <class V>
void copy_cells(const V& from, V& to, std::size_t first, std::size_t last) {
  std::copy(from.begin() + static_cast<std::ptrdiff_t>(first), from.begin() + static_cast<std::ptrdiff_t>(last),
            to.begin() + static_cast<std::ptrdiff_t>(first));
}

}  // namespace

DistanceField::DistanceField(const DistanceField& other)
    : width_(other.width_),
      height_(other.height_),
      resolution_(other.resolution_),
      segments_per_row_(other.segments_per_row_),
      below_(other.below_),
      above_(other.above_),
      bands_(other.bands_),
      segments_(other.segments_) {
  // Only what is ready in the copied flags is copied: the rest of other's storage may never have
  // been written (or is being written by another thread).
  const auto w = static_cast<std::size_t>(width_);
  column_.resize(other.column_.size());
  distance_.resize(other.distance_.size());
  for (std::size_t b = 0; b < bands_.size(); ++b) {
    if (!bands_.ready(b)) continue;
    const std::size_t first = b * kBandRows * w;
    copy_cells(other.column_, column_, first, std::min(column_.size(), first + kBandRows * w));
  }
  const auto per_row = static_cast<std::size_t>(segments_per_row_);
  for (std::size_t s = 0; s < segments_.size(); ++s) {
    if (!segments_.ready(s)) continue;
    const std::size_t first = (s / per_row) * w + (s % per_row) * kSegmentCells;
    copy_cells(other.distance_, distance_, first, std::min((s / per_row + 1) * w, first + kSegmentCells));
  }
}

DistanceField& DistanceField::operator=(const DistanceField& other) {
  if (this != &other) *this = DistanceField(other);
  return *this;
}

StopReason DistanceField::build(const std::uint8_t* occupied, int width, int height, double resolution,
                                const StopCondition& stop) {
  *this = DistanceField();
  const auto w = static_cast<std::size_t>(width);
  const int bands = (height + kBandRows - 1) / kBandRows;
  std::vector<std::uint32_t> below(static_cast<std::size_t>(bands) * w);
  std::vector<std::uint32_t> above(static_cast<std::size_t>(bands) * w);
  // Rolling distances along the columns, one whole row at a time (the compiler vectorises it).
  std::vector<std::uint32_t> d(w, 0U);  // row -1 is occupied
  for (int j = 0; j < height; ++j) {
    if (j % kStopCheckRows == 0) {
      if (const StopReason reason = stop.check(); reason != StopReason::kNone) return reason;
    }
    if (j % kBandRows == 0)
      std::copy(d.begin(), d.end(), below.begin() + static_cast<std::ptrdiff_t>((j / kBandRows) * w));
    const std::uint8_t* occ = occupied + static_cast<std::size_t>(j) * w;
    for (std::size_t i = 0; i < w; ++i) d[i] = occ[i] != 0 ? 0U : d[i] + 1U;
  }
  std::fill(d.begin(), d.end(), 0U);  // row height is occupied
  for (int j = height - 1; j >= 0; --j) {
    if (j % kStopCheckRows == 0) {
      if (const StopReason reason = stop.check(); reason != StopReason::kNone) return reason;
    }
    if (j == height - 1 || (j + 1) % kBandRows == 0) {
      std::copy(d.begin(), d.end(), above.begin() + static_cast<std::ptrdiff_t>((j / kBandRows) * w));
    }
    const std::uint8_t* occ = occupied + static_cast<std::size_t>(j) * w;
    for (std::size_t i = 0; i < w; ++i) d[i] = occ[i] != 0 ? 0U : d[i] + 1U;
  }
  width_ = width;
  height_ = height;
  resolution_ = resolution;
  segments_per_row_ = (width + kSegmentCells - 1) / kSegmentCells;
  below_ = std::move(below);
  above_ = std::move(above);
  column_.resize(w * static_cast<std::size_t>(height));  // uninitialised: filled per band
  distance_.resize(w * static_cast<std::size_t>(height));
  bands_ = FillFlags(static_cast<std::size_t>(bands));
  segments_ = FillFlags(static_cast<std::size_t>(height) * static_cast<std::size_t>(segments_per_row_));
  return StopReason::kNone;
}

void DistanceField::fill_band(int band, const std::uint8_t* occupied) const {
  const auto w = static_cast<std::size_t>(width_);
  const int j0 = band * kBandRows;
  const int j1 = std::min(height_, j0 + kBandRows);
  // Down from the band's lower edge, then up from its upper edge keeping the smaller.
  // Stored saturated at kMaxColumn (see column_).
  const auto store = [](std::uint32_t v) { return static_cast<std::uint16_t>(std::min(v, kMaxColumn)); };
  const std::uint32_t* seed = below_.data() + static_cast<std::size_t>(band) * w;
  std::uint16_t* g = column_.data() + static_cast<std::size_t>(j0) * w;
  for (std::size_t i = 0; i < w; ++i)
    g[i] = occupied[static_cast<std::size_t>(j0) * w + i] != 0 ? 0 : store(seed[i] + 1U);
  for (int j = j0 + 1; j < j1; ++j) {
    const std::uint8_t* occ = occupied + static_cast<std::size_t>(j) * w;
    const std::uint16_t* d = g;
    g += w;
    for (std::size_t i = 0; i < w; ++i) {
      // (a mask instead of a choice: the loop then vectorises)
      const std::uint16_t keep = occ[i] != 0 ? 0 : 0xFFFF;
      g[i] = static_cast<std::uint16_t>(store(d[i] + 1U) & keep);
    }
  }
  seed = above_.data() + static_cast<std::size_t>(band) * w;
  g = column_.data() + static_cast<std::size_t>(j1 - 1) * w;
  // (an occupied cell holds 0 already; min keeps it)
  for (std::size_t i = 0; i < w; ++i) g[i] = std::min(g[i], store(seed[i] + 1U));
  for (int j = j1 - 2; j >= j0; --j) {
    const std::uint16_t* u = g;
    g -= w;
    for (std::size_t i = 0; i < w; ++i) g[i] = std::min(g[i], store(u[i] + 1U));
  }
}

void DistanceField::fill(int ix, int iy, std::size_t segment, const std::uint8_t* occupied) const {
  bands_.ensure(static_cast<std::size_t>(iy >> kBandShift), [&] { fill_band(iy >> kBandShift, occupied); });
  segments_.ensure(segment, [&] {
    const int x0 = (ix >> kSegmentShift) << kSegmentShift;
    row_segment(iy, x0, std::min(width_, x0 + kSegmentCells), distance_.data() + index(x0, iy));
  });
}

namespace {

// The least of dx^2 + min(g(x + dx), cap + 1)^2 over |dx| <= cap for x = x0 .. x1 - 1 of a row
// (g: the row's first pass, `width` columns; columns -1 and width occupied) into out[0 .. x1 - x0):
// exact where the squared distance is below (cap + 1)^2, at least (cap + 1)^2 where it is not
// (0 < x1 - x0 <= DistanceField::kMaxCappedCells, 1 <= cap <= DistanceField::kMaxCap). The nearest
// occupied cell less than cap + 1 away lies in a column within cap, at a row distance of its
// column's g (at most cap): that term is exact, and every other term is a true squared distance or above
// (cap + 1)^2. 16-bit lanes: (cap + 1)^2 + cap^2 fits.
// (GCC on x86-64: an AVX2 clone too, chosen at load time where the CPU has it: twice the lanes,
// the same integers.)
#if defined(__GNUC__) && defined(__x86_64__) && !defined(__clang__)
__attribute__((target_clones("avx2", "default")))
#endif
void brute_force_row(const std::uint16_t* g, int width, int x0, int x1, int cap, std::int16_t* out) {
  std::array<std::int16_t, DistanceField::kMaxCappedCells + 2 * DistanceField::kMaxCap> sq;
  const auto far = static_cast<std::int16_t>((cap + 1) * (cap + 1));
  const int lo = x0 - cap;  // sq[k - lo] for the columns k = lo .. x1 - 1 + cap
  const int hi = x1 + cap;
  // The columns beyond -1 and width are never nearer than those two (occupied): `far`.
  const int in0 = std::max(lo, 0);
  const int in1 = std::min(hi, width);
  for (int k = lo; k < in0; ++k) sq[static_cast<std::size_t>(k - lo)] = k == -1 ? 0 : far;
  const auto limit = static_cast<std::uint16_t>(cap + 1);
  std::int16_t* inner = sq.data() + (in0 - lo);
  const std::uint16_t* column = g + in0;
  for (int k = 0; k < in1 - in0; ++k) {
    const int c = std::min(column[k], limit);
    inner[k] = static_cast<std::int16_t>(c * c);
  }
  for (int k = in1; k < hi; ++k) sq[static_cast<std::size_t>(k - lo)] = k == width ? 0 : far;
  const int n = x1 - x0;
  const std::int16_t* mid = sq.data() + cap;
  std::copy(mid, mid + n, out);
  for (int dx = 1; dx <= cap; ++dx) {
    const auto add = static_cast<std::int16_t>(dx * dx);
    const std::int16_t* right = mid + dx;
    const std::int16_t* left = mid - dx;
    for (int i = 0; i < n; ++i) {
      out[i] = std::min(out[i], static_cast<std::int16_t>(std::min(left[i], right[i]) + add));
    }
  }
}

}  // namespace

void DistanceField::capped_squared(int iy, int x0, int x1, int cap, std::int16_t* out,
                                   const std::uint8_t* occupied) const {
  bands_.ensure(static_cast<std::size_t>(iy >> kBandShift), [&] { fill_band(iy >> kBandShift, occupied); });
  brute_force_row(column_.data() + static_cast<std::size_t>(iy) * static_cast<std::size_t>(width_), width_, x0, x1, cap,
                  out);
}

void DistanceField::row_segment(int iy, int x0, int x1, float* out) const {
  const std::uint16_t* g = column_.data() + static_cast<std::size_t>(iy) * static_cast<std::size_t>(width_);
  // The columns -1 and width are occupied (distance 0 in every row).
  const auto f = [&](int k) -> double {
    if (k < 0 || k >= width_) return 0.0;
    const double v = g[k];
    return v * v;
  };
  // A cell's nearest occupied cell lies no farther than |x - k| + g(k) for any column k (the L1
  // distance to column k's nearest one; g = 0 on the border columns): the least of these over the
  // columns (two running minima, from the left and from the right) bounds each cell's distance
  // (as does the border), and the columns beyond the largest bound take no part. The running
  // minimum at x0 needs only the columns closer to x0 than the least found so far (a farther one
  // cannot beat it), a few in a lot, where the whole segment's width on either side was walked
  // before; likewise at x1 - 1. Any valid bound gives the same distances (integers, the minimum
  // over the window holding the nearest occupied cell); a tighter one a shorter envelope.
  const auto g_at = [&](int k) -> std::int64_t { return k < 0 || k >= width_ ? 0 : g[k]; };
  std::array<std::int64_t, kSegmentCells> forward;
  std::int64_t run = g_at(x0);
  // (at most a segment's width away, as before: a bound, never a long walk on an empty map)
  const int left_end = std::max(-1, x0 - kSegmentCells);
  const int right_end = std::min(width_, x1 - 1 + kSegmentCells);
  for (int k = x0 - 1; k >= left_end && x0 - k < run; --k) run = std::min(run, (x0 - k) + g_at(k));
  forward[0] = run;
  for (int k = x0 + 1; k < x1; ++k) {
    run = std::min<std::int64_t>(run + 1, g[k]);
    forward[k - x0] = run;
  }
  run = g_at(x1 - 1);
  for (int k = x1; k <= right_end && k - (x1 - 1) < run; ++k) run = std::min(run, (k - (x1 - 1)) + g_at(k));
  std::int64_t reach = 0;
  for (int k = x1 - 1; k >= x0; --k) {
    if (k < x1 - 1) run = std::min<std::int64_t>(run + 1, g[k]);
    reach = std::max(reach, std::min({run, forward[k - x0], std::int64_t{k} + 1, std::int64_t{width_} - k}));
  }
  if (reach <= kBruteForceReach) {
    // Every cell lies at most `reach` from an occupied one: the brute force capped there is exact
    // for all of them, and cheaper than the envelope below while the reach is short.
    std::array<std::int16_t, kSegmentCells> d2;
    brute_force_row(g, width_, x0, x1, static_cast<int>(std::max<std::int64_t>(reach, 1)), d2.data());
    for (int x = x0; x < x1; ++x) {
      out[x - x0] =
          static_cast<float>(std::sqrt(static_cast<double>(d2[static_cast<std::size_t>(x - x0)])) * resolution_);
    }
    return;
  }
  const int lo = static_cast<int>(std::max<std::int64_t>(-1, x0 - reach));
  const int hi = static_cast<int>(std::min<std::int64_t>(width_, x1 - 1 + reach));
  // Lower envelope of the parabolas (x - k)^2 + f(k), k = lo..hi (Felzenszwalb & Huttenlocher):
  // v holds the parabolas on it, z the boundaries between them. The numbers are integers below
  // 2^31 and the boundaries rationals with denominators below 2^16: two different ones differ by
  // far more than double's rounding, so no comparison is decided wrongly.
  const auto n = static_cast<std::size_t>(std::int64_t{hi} - lo + 1);
  // Scratch on the stack unless the window is unusually wide (a segment far from any obstacle):
  // per parabola on the envelope its column (v), f + column^2 (h), and where it begins (z).
  constexpr std::size_t kStackWindow = 1024;
  std::array<int, kStackWindow> v_stack;
  std::array<double, kStackWindow> h_stack;
  std::array<double, kStackWindow + 1> z_stack;
  std::vector<int> v_heap;
  std::vector<double> h_heap;
  std::vector<double> z_heap;
  int* v = v_stack.data();
  double* h = h_stack.data();
  double* z = z_stack.data();
  if (n > kStackWindow) {
    v_heap.resize(n);
    h_heap.resize(n);
    z_heap.resize(n + 1);
    v = v_heap.data();
    h = h_heap.data();
    z = z_heap.data();
  }
  std::size_t k = 0;
  v[0] = lo;
  h[0] = f(lo) + static_cast<double>(lo) * lo;
  z[0] = -std::numeric_limits<double>::infinity();
  z[1] = std::numeric_limits<double>::infinity();
  for (int q = lo + 1; q <= hi; ++q) {
    const double hq = f(q) + static_cast<double>(q) * q;
    double s = 0.0;
    while (true) {
      s = (hq - h[k]) / (2.0 * (q - v[k]));
      if (s > z[k]) break;  // z[0] = -inf ends the loop at k = 0
      --k;
    }
    ++k;
    v[k] = q;
    h[k] = hq;
    z[k] = s;
    z[k + 1] = std::numeric_limits<double>::infinity();
  }
  k = 0;
  for (int x = x0; x < x1; ++x) {
    while (z[k + 1] < static_cast<double>(x)) ++k;
    // (x - v)^2 + f(v) = h - 2 x v + x^2, exact in double (integers below 2^53)
    const double d2 = h[k] + static_cast<double>(x) * (x - 2.0 * v[k]);
    out[x - x0] = static_cast<float>(std::sqrt(d2) * resolution_);
  }
}

}  // namespace pullout
