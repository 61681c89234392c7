// Nearest-rank percentiles of a benchmark's samples (shared by the DDS benchmarks).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace pullout::bench {

struct Summary {
  std::size_t n{0};
  double p50{0}, p90{0}, p95{0}, p99{0}, max{0};
};

// Nearest rank: the smallest sample with at least q of the samples at or below it.
inline Summary summarize(std::vector<double> v) {
  Summary s;
  s.n = v.size();
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  const auto rank = [&](double q) {
    const auto k = static_cast<std::size_t>(std::ceil(q * static_cast<double>(v.size())));
    return v[std::min(v.size() - 1, k == 0 ? 0 : k - 1)];
  };
  s.p50 = rank(0.50);
  s.p90 = rank(0.90);
  s.p95 = rank(0.95);
  s.p99 = rank(0.99);
  s.max = v.back();
  return s;
}

}  // namespace pullout::bench
