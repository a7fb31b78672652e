#include "core/mask_scan.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

namespace parallax {
namespace {

std::vector<int> Visited(const std::vector<std::uint8_t>& mask, int begin, int end) {
  std::vector<int> visited;
  ForEachColumnNearMask(mask.data(), begin, end, [&](int x) { visited.push_back(x); });
  return visited;
}

TEST(ForEachColumnNearMask, VisitsEveryNonZeroColumnInOrderAndSkipsOnlyAllZeroGroups) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    const int width = 1 + static_cast<int>(rng() % 70);
    std::vector<std::uint8_t> mask(static_cast<std::size_t>(width), 0);
    // Sparse runs, as in a semi-dense map.
    for (int x = 0; x < width; ++x) mask[static_cast<std::size_t>(x)] = rng() % 9 == 0 ? 3 : 0;
    const int begin = static_cast<int>(rng() % static_cast<unsigned>(width));
    const int end = begin + static_cast<int>(rng() % static_cast<unsigned>(width - begin + 1));
    const std::vector<int> visited = Visited(mask, begin, end);
    std::vector<int> expected;
    for (int x0 = begin; x0 < end; x0 += 8) {
      const int x1 = std::min(x0 + 8, end);
      bool any = x1 - x0 < 8;
      for (int x = x0; x < x1; ++x) any = any || mask[static_cast<std::size_t>(x)] != 0;
      for (int x = x0; any && x < x1; ++x) expected.push_back(x);
    }
    ASSERT_EQ(visited, expected) << "width " << width << " begin " << begin << " end " << end;
    for (int x = begin; x < end; ++x) {
      if (mask[static_cast<std::size_t>(x)] == 0) continue;
      EXPECT_NE(std::find(visited.begin(), visited.end(), x), visited.end());
    }
  }
}

TEST(ForEachColumnNearMask, AnAllZeroRowOfWholeGroupsVisitsNothingAndAFullRowEverything) {
  EXPECT_TRUE(Visited(std::vector<std::uint8_t>(64, 0), 0, 64).empty());
  EXPECT_EQ(Visited(std::vector<std::uint8_t>(64, 0), 0, 61).size(), 5u);  // the partial group
  EXPECT_EQ(Visited(std::vector<std::uint8_t>(64, 1), 3, 64).size(), 61u);
  EXPECT_TRUE(Visited(std::vector<std::uint8_t>(8, 1), 4, 4).empty());
}

}  // namespace
}  // namespace parallax
