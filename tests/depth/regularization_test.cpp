// DepthFilter::Regularize over a whole map (depth/depth_regularization.cpp): its row work
// lists give, bit for bit, what the rule gives applied to every pixel of the image in turn
// (docs/math/depth_filter.md, "Regularisation and hole filling").

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#include "core/divergence.hpp"
#include "core/frame.hpp"
#include "depth/depth_filter.hpp"
#include "depth/regularize_kernel.hpp"

namespace parallax {
namespace {

constexpr int kWidth = 67, kHeight = 41;  // odd sizes: the lists' eight-column groups end partial

std::shared_ptr<const Frame> RandomKeyframe(std::mt19937* rng) {
  ImageU8 image(kWidth, kHeight, 0);
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) image(x, y) = static_cast<std::uint8_t>((*rng)() % 256);
  }
  const PinholeCamera camera(kWidth, kHeight, 50.0, 50.0, 33.0, 20.0);
  return std::make_shared<const Frame>(0, 0.0, camera, image);
}

// Dense on the left (most pixels kept or voted out), sparse on the right (too little
// support), valid pixels on the border too, some of them diverged, and junk in invalid ones.
InverseDepthMap RandomMap(std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  InverseDepthMap map(RandomKeyframe(&rng), DepthFilterOptions{});
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      const std::size_t i = map.Index(x, y);
      const bool valid = unit(rng) < (x < kWidth / 2 ? 0.6f : 0.08f);
      map.valid[i] = valid ? 1 : 0;
      map.observations[i] = static_cast<std::uint16_t>(unit(rng) < 0.7f ? 1 + rng() % 5 : 0);
      map.validity[i] = valid ? 30.0f * unit(rng) - 5.0f : 0.0f;
      map.idepth[i] = (unit(rng) < 0.3f ? 2.0f : 1.0f) + 0.05f * unit(rng);  // two surfaces
      map.variance[i] = 1e-4f + 4e-3f * unit(rng) * unit(rng);
      if (!valid || unit(rng) < 0.02f) {
        const float junk[] = {nan, std::numeric_limits<float>::infinity(), -3.0f, 0.0f};
        (rng() % 2 ? map.idepth[i] : map.variance[i]) = junk[rng() % 4];
      }
    }
  }
  return map;
}

// The rule pixel by pixel over the whole image: diverged estimates removed, every valid pixel
// at least 2 from the border regularised from the inputs of all, then the removals (the
// window's margin, too little support, outvoted, an unhealthy result).
int ReferenceRegularize(const DepthFilterOptions& options, InverseDepthMap* map) {
  const std::size_t n = map->valid.size();
  int diverged = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (map->valid[i] && !HealthyEstimate(map->idepth[i], map->variance[i])) {
      map->Invalidate(i);
      ++diverged;
    }
  }
  RegularizeInputs in;
  in.width = kWidth;
  in.idepth = map->idepth.data();
  in.variance = map->variance.data();
  in.inv_var.assign(n, 0.0f);
  in.support.assign(n, 0.0f);
  in.vote.assign(n, 0.0f);
  for (std::size_t i = 0; i < n; ++i) {
    if (!map->valid[i]) continue;
    in.inv_var[i] = 1.0f / map->variance[i];
    in.support[i] = map->validity[i];
    in.vote[i] = map->observations[i] > 0 ? map->validity[i] : 0.0f;
  }
  for (int dy = -2; dy <= 2; ++dy) {
    for (int dx = -2; dx <= 2; ++dx) {
      const int k = (dy + 2) * 5 + dx + 2;
      in.decay[static_cast<std::size_t>(k)] =
          1.0f / (1.0f + 0.1f * static_cast<float>(dx * dx + dy * dy));
    }
  }
  std::vector<std::uint8_t> keep(n, 0);
  for (int y = 2; y < kHeight - 2; ++y) {
    for (int x = 2; x < kWidth - 2; ++x) {
      const std::size_t i = map->Index(x, y);
      if (!map->valid[i]) continue;
      const RegularizedPixel r = RegularizePixelScalar(in, i);
      map->idepth_smoothed[i] = r.idepth;
      map->variance_smoothed[i] = r.variance;
      keep[i] = r.support >= options.min_neighbour_validity && !(r.disagree > r.agree) &&
                HealthyEstimate(r.idepth, r.variance);
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (map->valid[i] && !keep[i]) map->Invalidate(i);
  }
  return diverged;
}

bool SameBits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

TEST(DepthFilterRegularize, GivesBitForBitWhatTheRuleGivesPixelByPixel) {
  const DepthFilter filter;
  for (std::uint32_t seed = 1; seed <= 5; ++seed) {
    InverseDepthMap map = RandomMap(seed);
    InverseDepthMap expected = RandomMap(seed);
    const int expected_diverged = ReferenceRegularize(filter.Options(), &expected);
    ASSERT_GT(expected_diverged, 0);
    // Both outcomes occur: kept estimates, and removed ones beyond the diverged.
    const std::size_t valid_before = RandomMap(seed).NumValid();
    ASSERT_GT(expected.NumValid(), valid_before / 4);
    ASSERT_LT(expected.NumValid() + static_cast<std::size_t>(expected_diverged), valid_before);
    EXPECT_EQ(filter.Regularize(&map), expected_diverged) << "seed " << seed;
    EXPECT_EQ(map.valid, expected.valid) << "seed " << seed;
    EXPECT_EQ(map.observations, expected.observations) << "seed " << seed;
    EXPECT_TRUE(SameBits(map.validity, expected.validity)) << "seed " << seed;
    EXPECT_TRUE(SameBits(map.idepth_smoothed, expected.idepth_smoothed)) << "seed " << seed;
    EXPECT_TRUE(SameBits(map.variance_smoothed, expected.variance_smoothed)) << "seed " << seed;
    // Nothing on the window's margin survives.
    for (int y = 0; y < kHeight; ++y) {
      for (int x = 0; x < kWidth; ++x) {
        if (x >= 2 && x < kWidth - 2 && y >= 2 && y < kHeight - 2) continue;
        EXPECT_EQ(map.valid[map.Index(x, y)], 0) << x << "," << y;
      }
    }
  }
}

}  // namespace
}  // namespace parallax
