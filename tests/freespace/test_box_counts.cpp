// The lazily filled summed-area table. Oracle: counting the cells of each box one by one.
#include "pullout/freespace/box_counts.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <random>
#include <thread>
#include <utility>
#include <vector>

namespace pullout {
namespace {

struct Grid {
  int width{0};
  int height{0};
  std::vector<std::uint8_t> cells;
};

Grid random_grid(int width, int height, double density, std::mt19937& rng) {
  Grid g{width, height, std::vector<std::uint8_t>(static_cast<std::size_t>(width) * height, 0)};
  std::bernoulli_distribution set(density);
  std::uniform_int_distribution<int> value(1, 255);  // any non-zero value counts once
  for (auto& c : g.cells) c = set(rng) ? static_cast<std::uint8_t>(value(rng)) : 0;
  return g;
}

int oracle(const Grid& g, int c0, int r0, int c1, int r1) {
  int n = 0;
  for (int r = r0; r <= r1; ++r) {
    for (int c = c0; c <= c1; ++c) n += g.cells[static_cast<std::size_t>(r) * g.width + c] != 0 ? 1 : 0;
  }
  return n;
}

struct Box {
  int c0, r0, c1, r1;
};

Box random_box(const Grid& g, std::mt19937& rng) {
  std::uniform_int_distribution<int> x(0, g.width - 1), y(0, g.height - 1);
  int c0 = x(rng), c1 = x(rng), r0 = y(rng), r1 = y(rng);
  if (c1 < c0) std::swap(c0, c1);
  if (r1 < r0) std::swap(r0, r1);
  return {c0, r0, c1, r1};
}

TEST(BoxCounts, MatchesCountingOnRandomGrids) {
  std::mt19937 rng(17);
  const std::pair<int, int> sizes[] = {{1, 1}, {70, 63}, {70, 64}, {33, 65}, {1, 300}, {300, 1}, {200, 150}};
  for (const auto& [w, h] : sizes) {
    for (const double density : {0.0, 0.05, 0.5, 1.0}) {
      SCOPED_TRACE(testing::Message() << w << "x" << h << " density " << density);
      const Grid g = random_grid(w, h, density, rng);
      BoxCounts counts;
      ASSERT_EQ(counts.build(g.cells.data(), w, h), StopReason::kNone);
      // Boxes in a random order (bands filled in any order), the whole grid and single cells too.
      EXPECT_EQ(counts.count(0, 0, w - 1, h - 1, g.cells.data()), oracle(g, 0, 0, w - 1, h - 1));
      for (int k = 0; k < 300; ++k) {
        const Box b = random_box(g, rng);
        ASSERT_EQ(counts.count(b.c0, b.r0, b.c1, b.r1, g.cells.data()), oracle(g, b.c0, b.r0, b.c1, b.r1))
            << b.c0 << "," << b.r0 << " .. " << b.c1 << "," << b.r1;
        ASSERT_EQ(counts.count(b.c0, b.r1, b.c0, b.r1, g.cells.data()), oracle(g, b.c0, b.r1, b.c0, b.r1));
      }
    }
  }
}

TEST(BoxCounts, RowCountsMatchCountingOnFreshTables) {
  // Every row of a fresh table (so each band is first filled by count_row, including the rows
  // whose next table row starts the next band), at random column ranges.
  std::mt19937 rng(77);
  for (const auto& [w, h] : {std::pair{37, 200}, std::pair{1, 65}, std::pair{130, 64}}) {
    const Grid g = random_grid(w, h, 0.3, rng);
    BoxCounts counts;
    ASSERT_EQ(counts.build(g.cells.data(), g.width, g.height), StopReason::kNone);
    for (int r = h - 1; r >= 0; --r) {
      int c0 = std::uniform_int_distribution<int>(0, w - 1)(rng);
      int c1 = std::uniform_int_distribution<int>(0, w - 1)(rng);
      if (c0 > c1) std::swap(c0, c1);
      ASSERT_EQ(counts.count_row(c0, c1, r, g.cells.data()), oracle(g, c0, r, c1, r))
          << w << " x " << h << " row " << r;
    }
  }
}

TEST(BoxCounts, FillsOnlyTheBandsAskedFor) {
  std::mt19937 rng(2);
  const Grid g = random_grid(50, 300, 0.1, rng);  // table rows 0..300: bands 0..4
  BoxCounts counts;
  ASSERT_EQ(counts.build(g.cells.data(), 50, 300), StopReason::kNone);
  EXPECT_EQ(counts.filled_bands(), 0U);
  EXPECT_EQ(counts.count(3, 200, 40, 210, g.cells.data()), oracle(g, 3, 200, 40, 210));  // table rows 200, 211
  EXPECT_EQ(counts.filled_bands(), 1U);
  EXPECT_EQ(counts.count(0, 10, 49, 299, g.cells.data()), oracle(g, 0, 10, 49, 299));  // rows 10 and 300
  EXPECT_EQ(counts.filled_bands(), 3U);
}

TEST(BoxCounts, CopyAndConcurrentReaders) {
  std::mt19937 rng(4);
  const Grid g = random_grid(120, 200, 0.2, rng);
  BoxCounts counts;
  ASSERT_EQ(counts.build(g.cells.data(), 120, 200), StopReason::kNone);
  (void)counts.count(0, 70, 5, 80, g.cells.data());
  const BoxCounts copy = counts;
  EXPECT_EQ(copy.filled_bands(), counts.filled_bands());
  std::vector<Box> boxes;
  std::vector<int> truth;
  for (int k = 0; k < 400; ++k) {
    boxes.push_back(random_box(g, rng));
    truth.push_back(oracle(g, boxes.back().c0, boxes.back().r0, boxes.back().c1, boxes.back().r1));
  }
  std::atomic<int> wrong{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&, t] {
      const BoxCounts& c = t % 2 == 0 ? counts : copy;
      for (std::size_t k = 0; k < boxes.size(); ++k) {
        const Box& b = boxes[(k * 7 + static_cast<std::size_t>(t) * 101) % boxes.size()];
        if (c.count(b.c0, b.r0, b.c1, b.r1, g.cells.data()) !=
            truth[(k * 7 + static_cast<std::size_t>(t) * 101) % boxes.size()]) {
          ++wrong;
        }
      }
    });
  }
  for (auto& t : threads) t.join();
  EXPECT_EQ(wrong.load(), 0);
}

TEST(BoxCounts, StopsWhenTold) {
  const Grid g{10, 10, std::vector<std::uint8_t>(100, 0)};
  std::atomic<bool> cancel{true};
  BoxCounts counts;
  EXPECT_EQ(counts.build(g.cells.data(), 10, 10, StopCondition().with_cancel(&cancel)), StopReason::kCancelled);
  EXPECT_TRUE(counts.empty());
}

}  // namespace
}  // namespace pullout
