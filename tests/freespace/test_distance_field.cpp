// The lazy distance transform. Oracle: brute force over every occupied cell and the border (the
// cells one beyond the grid), in integers, independent of the two passes under test.
#include "pullout/freespace/distance_field.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <random>
#include <thread>
#include <vector>

namespace pullout {
namespace {

struct Grid {
  int width{0};
  int height{0};
  std::vector<std::uint8_t> occupied;
};

Grid random_grid(int width, int height, double density, std::mt19937& rng) {
  Grid g{width, height, std::vector<std::uint8_t>(static_cast<std::size_t>(width) * height, 0)};
  std::bernoulli_distribution occupied(density);
  for (auto& c : g.occupied) c = occupied(rng) ? 1 : 0;
  return g;
}

// Squared distance in cells from cell (i, j) to the nearest occupied cell or border cell.
std::int64_t oracle_squared(const Grid& g, int i, int j) {
  // The nearest border cell lies straight across (the border is a full ring one cell outside).
  const std::int64_t border = std::min({i + 1, j + 1, g.width - i, g.height - j});
  std::int64_t best = border * border;
  for (int y = 0; y < g.height; ++y) {
    for (int x = 0; x < g.width; ++x) {
      if (g.occupied[static_cast<std::size_t>(y) * g.width + x] == 0) continue;
      const std::int64_t dx = x - i;
      const std::int64_t dy = y - j;
      best = std::min(best, dx * dx + dy * dy);
    }
  }
  return best;
}

// The value the contract promises: sqrt of the squared cell distance times the resolution, as float.
float expected(const Grid& g, int i, int j, double resolution) {
  return static_cast<float>(std::sqrt(static_cast<double>(oracle_squared(g, i, j))) * resolution);
}

// Every cell, asked in a random order (segments filled in any order, from any of their cells).
void expect_matches_oracle(const Grid& g, double resolution, std::mt19937& rng) {
  DistanceField field;
  ASSERT_EQ(field.build(g.occupied.data(), g.width, g.height, resolution), StopReason::kNone);
  std::vector<int> order(static_cast<std::size_t>(g.width) * g.height);
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), rng);
  for (const int c : order) {
    const int i = c % g.width;
    const int j = c / g.width;
    ASSERT_EQ(field.at(i, j, g.occupied.data()), expected(g, i, j, resolution))
        << "cell " << i << "," << j << " of " << g.width << "x" << g.height;
  }
}

TEST(DistanceField, MatchesBruteForceOnRandomMaps) {
  std::mt19937 rng(11);
  // Sizes around the segment width (64), a single row and a single column; densities from an
  // empty grid (only the border: the largest windows) to a crowded one.
  const std::pair<int, int> sizes[] = {{150, 97}, {64, 64}, {65, 3}, {1, 130}, {200, 1}, {129, 40}};
  for (const auto& [w, h] : sizes) {
    for (const double density : {0.0, 0.002, 0.03, 0.3}) {
      SCOPED_TRACE(testing::Message() << w << "x" << h << " density " << density);
      expect_matches_oracle(random_grid(w, h, density, rng), 0.1, rng);
    }
  }
}

// The capped squared distances of a row range: exact below (cap + 1)^2, at least that beyond.
// Ranges at the grid's left and right edges (the border columns inside the window) and inside;
// caps of one cell, of a few, and the largest allowed; grids narrower than the window.
TEST(DistanceField, CappedSquaredIsExactBelowTheCapAndAtLeastItBeyond) {
  std::mt19937 rng(17);
  const std::pair<int, int> sizes[] = {{300, 40}, {20, 30}, {1, 12}, {257, 9}};
  int exact = 0;
  int capped = 0;
  for (const auto& [w, h] : sizes) {
    for (const double density : {0.0, 0.01, 0.3}) {
      const Grid g = random_grid(w, h, density, rng);
      DistanceField field;
      ASSERT_EQ(field.build(g.occupied.data(), g.width, g.height, 0.1), StopReason::kNone);
      for (const int cap : {1, 3, 29, DistanceField::kMaxCap}) {
        std::uniform_int_distribution<int> length(1, std::min(w, DistanceField::kMaxCappedCells));
        for (int k = 0; k < 6; ++k) {
          const int n = length(rng);
          const int x0 = k == 0 ? 0 : k == 1 ? w - n : std::uniform_int_distribution<int>(0, w - n)(rng);
          const int iy = std::uniform_int_distribution<int>(0, h - 1)(rng);
          std::vector<std::int16_t> out(static_cast<std::size_t>(n));
          field.capped_squared(iy, x0, x0 + n, cap, out.data(), g.occupied.data());
          for (int i = 0; i < n; ++i) {
            const std::int64_t truth = oracle_squared(g, x0 + i, iy);
            const std::int64_t got = out[static_cast<std::size_t>(i)];
            SCOPED_TRACE(testing::Message() << w << "x" << h << " density " << density << " cap " << cap << " cell "
                                            << x0 + i << "," << iy);
            if (truth < std::int64_t{cap + 1} * (cap + 1)) {
              ASSERT_EQ(got, truth);
              ++exact;
            } else {
              ASSERT_GE(got, std::int64_t{cap + 1} * (cap + 1));
              ++capped;
            }
          }
        }
      }
    }
  }
  // Both kinds of cell were compared many times.
  EXPECT_GT(exact, 1000);
  EXPECT_GT(capped, 1000);
}

TEST(DistanceField, MatchesBruteForceAroundLongWalls) {
  // Walls with gaps and a large open room: the nearest obstacle of many cells lies far along the
  // row, beyond their segment.
  std::mt19937 rng(3);
  Grid g{300, 120, std::vector<std::uint8_t>(300 * 120, 0)};
  for (int x = 0; x < 300; ++x) {
    if (x % 97 > 4) g.occupied[static_cast<std::size_t>(30) * 300 + x] = 1;
  }
  for (int y = 50; y < 120; ++y) g.occupied[static_cast<std::size_t>(y) * 300 + 250] = 1;
  g.occupied[static_cast<std::size_t>(90) * 300 + 7] = 1;
  expect_matches_oracle(g, 0.2, rng);
}

TEST(DistanceField, ExactOnAGridTallerThanTheStoredColumnDistances) {
  // 140,000 rows: column distances up to 70,000 saturate in storage (at 65,535), which must not
  // change a distance (the border is nearer than any saturated column). Width 4: the column
  // pass's row loops run their scalar tail only; width 40: their vectorised body too (several
  // 16-bit lanes per step), where a wrapped instead of saturated distance would read as 0.
  for (const int width : {4, 40}) {
    SCOPED_TRACE(testing::Message() << "width " << width);
    std::mt19937 rng(9);
    Grid g{width, 140000, std::vector<std::uint8_t>(static_cast<std::size_t>(width) * 140000, 0)};
    const int rows[] = {5, 70000, 139990};
    for (const int r : rows) g.occupied[static_cast<std::size_t>(r) * width + 1] = 1;
    // The oracle over the three occupied cells and the border (the grid is too large to scan per cell).
    const auto truth = [&](int i, int j) {
      std::int64_t best = std::min({i + 1, j + 1, g.width - i, g.height - j});
      best *= best;
      for (const int r : rows)
        best = std::min<std::int64_t>(best, std::int64_t{i - 1} * (i - 1) + std::int64_t{j - r} * (j - r));
      return static_cast<float>(std::sqrt(static_cast<double>(best)) * 0.1);
    };
    DistanceField field;
    ASSERT_EQ(field.build(g.occupied.data(), g.width, g.height, 0.1), StopReason::kNone);
    std::uniform_int_distribution<int> row(0, g.height - 1), col(0, g.width - 1);
    for (int k = 0; k < 3000; ++k) {
      const int i = k < 16 ? k % g.width : col(rng);
      const int j = k < 8 ? 69996 + k : k < 16 ? 65530 + k : row(rng);
      ASSERT_EQ(field.at(i, j, g.occupied.data()), truth(i, j)) << i << "," << j;
    }
  }
}

TEST(DistanceField, FillsOnlyTheSegmentsAskedFor) {
  constexpr int kSeg = DistanceField::kSegmentCells;
  std::mt19937 rng(5);
  const Grid g = random_grid(2 * kSeg + 44, 70, 0.01, rng);  // rows of three segments, the last short
  DistanceField field;
  ASSERT_EQ(field.build(g.occupied.data(), g.width, g.height, 0.1), StopReason::kNone);
  EXPECT_EQ(field.filled_segments(), 0U);
  EXPECT_EQ(field.filled_bands(), 0U);
  EXPECT_EQ(field.at(kSeg + 2, 20, g.occupied.data()), expected(g, kSeg + 2, 20, 0.1));
  EXPECT_EQ(field.filled_segments(), 1U);
  EXPECT_EQ(field.at(kSeg, 20, g.occupied.data()), expected(g, kSeg, 20, 0.1));  // the same segment
  EXPECT_EQ(field.filled_segments(), 1U);
  EXPECT_EQ(field.at(kSeg - 1, 20, g.occupied.data()), expected(g, kSeg - 1, 20, 0.1));        // the one before it
  EXPECT_EQ(field.at(g.width - 1, 63, g.occupied.data()), expected(g, g.width - 1, 63, 0.1));  // the short last one
  EXPECT_EQ(field.filled_segments(), 3U);
  EXPECT_EQ(field.filled_bands(), 1U);  // rows 0..63
  EXPECT_EQ(field.at(0, 64, g.occupied.data()), expected(g, 0, 64, 0.1));
  EXPECT_EQ(field.filled_bands(), 2U);
}

TEST(DistanceField, CopyKeepsFilledValuesAndFillsTheRestItself) {
  std::mt19937 rng(8);
  const Grid g = random_grid(140, 30, 0.02, rng);
  DistanceField field;
  ASSERT_EQ(field.build(g.occupied.data(), g.width, g.height, 0.1), StopReason::kNone);
  for (int j = 0; j < 30; j += 3) (void)field.at(70, j, g.occupied.data());
  const DistanceField copy = field;
  EXPECT_EQ(copy.filled_segments(), field.filled_segments());
  for (int j = 0; j < g.height; ++j) {
    for (int i = 0; i < g.width; ++i)
      ASSERT_EQ(copy.at(i, j, g.occupied.data()), expected(g, i, j, 0.1)) << i << "," << j;
  }
  EXPECT_EQ(field.filled_segments(), 10U);  // the copy's fills are its own
  DistanceField assigned;
  assigned = copy;
  EXPECT_EQ(assigned.filled_segments(), copy.filled_segments());
  EXPECT_EQ(assigned.at(3, 4, g.occupied.data()), expected(g, 3, 4, 0.1));
}

TEST(DistanceField, ConcurrentReadersGetTheSameValues) {
  std::mt19937 rng(21);
  const Grid g = random_grid(256, 64, 0.01, rng);
  std::vector<float> truth(g.occupied.size());
  for (int j = 0; j < g.height; ++j) {
    for (int i = 0; i < g.width; ++i) truth[static_cast<std::size_t>(j) * g.width + i] = expected(g, i, j, 0.1);
  }
  DistanceField field;
  ASSERT_EQ(field.build(g.occupied.data(), g.width, g.height, 0.1), StopReason::kNone);
  std::atomic<int> wrong{0};
  std::vector<std::thread> threads;
  for (unsigned t = 0; t < 4; ++t) {
    threads.emplace_back([&, t] {
      // Each thread walks the cells in its own order: many segments are asked for by several at once.
      std::mt19937 local(t);
      std::vector<int> order(truth.size());
      std::iota(order.begin(), order.end(), 0);
      std::shuffle(order.begin(), order.end(), local);
      for (const int c : order) {
        if (field.at(c % g.width, c / g.width, g.occupied.data()) != truth[static_cast<std::size_t>(c)]) ++wrong;
      }
    });
  }
  for (auto& t : threads) t.join();
  EXPECT_EQ(wrong.load(), 0);
  EXPECT_EQ(field.filled_segments(), static_cast<std::size_t>(64 * (256 / DistanceField::kSegmentCells)));
}

TEST(DistanceField, StopsWhenTold) {
  const Grid g{100, 200, std::vector<std::uint8_t>(100 * 200, 0)};
  std::atomic<bool> cancel{true};
  DistanceField field;
  EXPECT_EQ(field.build(g.occupied.data(), g.width, g.height, 0.1, StopCondition().with_cancel(&cancel)),
            StopReason::kCancelled);
  EXPECT_TRUE(field.empty());
}

}  // namespace
}  // namespace pullout
