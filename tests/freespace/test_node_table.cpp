// The hybrid A*'s lattice node table (search_support.hpp): every key keeps its own slot through
// the table's growth. Keys as the search makes them: column bits from 41 up, row bits from 20,
// heading bits at the bottom (the columns are what the old slot index ignored).
#include <gtest/gtest.h>

#include <cstdint>
#include <map>
#include <random>

#include "search_support.hpp"

namespace pullout {
namespace {

namespace fd = freespace_detail;

std::uint64_t lattice_key(std::uint64_t column, std::uint64_t row, std::uint64_t heading, bool fine) {
  return (fine ? 1ULL << 62 : 0) | (column << 41) | (row << 20) | heading;
}

TEST(NodeTable, EveryKeyKeepsItsValueThroughGrowth) {
  fd::NodeTable table;
  std::map<std::uint64_t, std::int32_t> expected;
  // A whole block of the lattice (rows of cells differing in their column only), then random keys.
  std::int32_t next = 0;
  for (std::uint64_t column = 0; column < 120; ++column) {
    for (std::uint64_t heading = 0; heading < 72; heading += 7) {
      const std::uint64_t key = lattice_key((1 << 19) + column, (1 << 19) + 3, heading, false);
      std::int32_t* slot = table.find_or_insert(key);
      ASSERT_EQ(*slot, -1);
      *slot = next;
      expected[key] = next++;
    }
  }
  std::mt19937_64 rng(7);
  std::uniform_int_distribution<std::uint64_t> cell(0, (1 << 20) - 1), heading(0, 71);
  for (int k = 0; k < 20000; ++k) {
    const std::uint64_t key = lattice_key(cell(rng), cell(rng), heading(rng), (k % 3) == 0);
    std::int32_t* slot = table.find_or_insert(key);
    const auto it = expected.find(key);
    if (it == expected.end()) {
      ASSERT_EQ(*slot, -1);
      *slot = next;
      expected[key] = next++;
    } else {
      ASSERT_EQ(*slot, it->second);
    }
  }
  EXPECT_EQ(table.size(), expected.size());
  for (const auto& [key, value] : expected) ASSERT_EQ(*table.find_or_insert(key), value);
  EXPECT_EQ(table.size(), expected.size());  // finding adds nothing
}

}  // namespace
}  // namespace pullout
