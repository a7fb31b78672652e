#include "core/rounding.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace parallax {
namespace {

TEST(RoundHalfAwayFromZero, EqualsLroundAtHalvesTheirNeighboursAndRandomValues) {
  std::vector<float> values = {0.0f,  -0.0f,       0.5f,       -0.5f,       1.5f, -1.5f, 2.5f,
                               -2.5f, 1e6f + 0.5f, 8388607.5f, 16777216.0f, 1e9f, -1e9f};
  for (const float half : {0.5f, 1.5f, 2.5f, 100.5f, 1225.5f}) {
    for (const float x : {half, -half}) {
      values.push_back(std::nextafter(x, 0.0f));  // e.g. 0.49999997: rounds towards zero
      values.push_back(std::nextafter(x, 2.0f * x));
    }
  }
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> coordinate(-3000.0f, 3000.0f);
  for (int i = 0; i < 100000; ++i) values.push_back(coordinate(rng));
  for (const float x : values) {
    ASSERT_EQ(RoundHalfAwayFromZero(x), static_cast<int>(std::lround(x))) << x;
  }
}

}  // namespace
}  // namespace parallax
