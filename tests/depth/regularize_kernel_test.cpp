// The 5x5 regularisation kernel: the SSE2 kernel equals its scalar twin bit for bit, and both
// equal a plain double-precision reference of the rule (compatible neighbours averaged by
// inverse variance, support summed, observed neighbours other than the pixel voting).

#include "depth/regularize_kernel.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>

namespace parallax {
namespace {

struct RandomMap {
  int width = 64, height = 48;
  std::vector<float> idepth, variance, validity;
  std::vector<std::uint8_t> valid, observed;
  RegularizeInputs in;

  std::size_t At(int x, int y) const {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
           static_cast<std::size_t>(x);
  }

  explicit RandomMap(std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    const std::size_t n = At(0, height);
    idepth.resize(n);
    variance.resize(n);
    validity.resize(n);
    valid.resize(n);
    observed.resize(n);
    in.width = width;
    in.inv_var.assign(n, 0.0f);
    in.support.assign(n, 0.0f);
    in.vote.assign(n, 0.0f);
    for (std::size_t i = 0; i < n; ++i) {
      valid[i] = unit(rng) < 0.45f;
      observed[i] = unit(rng) < 0.7f;
      validity[i] = 30.0f * unit(rng) - 5.0f;
      // Two surfaces, so that some neighbours are incompatible.
      idepth[i] = (unit(rng) < 0.3f ? 2.0f : 1.0f) + 0.05f * unit(rng);
      variance[i] = 1e-4f + 4e-3f * unit(rng) * unit(rng);
      if (!valid[i]) {
        // Invalid pixels may hold anything (a diverged estimate that was removed).
        const float junk[] = {std::numeric_limits<float>::quiet_NaN(),
                              std::numeric_limits<float>::infinity(), -3.0f, 0.0f};
        idepth[i] = junk[i % 4];
        variance[i] = junk[(i / 4) % 4];
        continue;
      }
      in.inv_var[i] = 1.0f / variance[i];
      in.support[i] = validity[i];
      in.vote[i] = observed[i] ? validity[i] : 0.0f;
    }
    in.idepth = idepth.data();
    in.variance = variance.data();
    for (int dy = -2; dy <= 2; ++dy) {
      for (int dx = -2; dx <= 2; ++dx) {
        in.decay[static_cast<std::size_t>(dy + 2) * 5 + static_cast<std::size_t>(dx + 2)] =
            1.0f / (1.0f + 0.1f * static_cast<float>(dx * dx + dy * dy));
      }
    }
  }
};

RegularizedPixel Reference(const RandomMap& m, int x, int y) {
  const std::size_t i = m.At(x, y);
  double sum_w = 0, sum_wd = 0;
  RegularizedPixel out;
  for (int dy = -2; dy <= 2; ++dy) {
    for (int dx = -2; dx <= 2; ++dx) {
      const std::size_t j = m.At(x + dx, y + dy);
      if (!m.valid[j]) continue;
      out.support += m.validity[j];
      const double diff = m.idepth[j] - m.idepth[i];
      const bool compatible = diff * diff <= m.variance[i] + m.variance[j];
      if (j != i && m.observed[j]) (compatible ? out.agree : out.disagree) += m.validity[j];
      if (!compatible) continue;
      const double w = 1.0 / (m.variance[j] * (1.0 + 0.1 * (dx * dx + dy * dy)));
      sum_w += w;
      sum_wd += w * m.idepth[j];
    }
  }
  out.idepth = static_cast<float>(sum_wd / sum_w);
  out.variance = std::min(m.variance[i], static_cast<float>(1.0 / sum_w));
  return out;
}

bool SameBits(float a, float b) {
  std::uint32_t bits_a = 0, bits_b = 0;
  std::memcpy(&bits_a, &a, sizeof(float));
  std::memcpy(&bits_b, &b, sizeof(float));
  return bits_a == bits_b;
}

bool SameBits(const RegularizedPixel& a, const RegularizedPixel& b) {
  return SameBits(a.idepth, b.idepth) && SameBits(a.variance, b.variance) &&
         SameBits(a.support, b.support) && SameBits(a.agree, b.agree) &&
         SameBits(a.disagree, b.disagree);
}

TEST(RegularizeKernel, SimdEqualsScalarTwinBitForBitAndTheRule) {
  int checked = 0;
  for (std::uint32_t seed = 1; seed <= 4; ++seed) {
    const RandomMap m(seed);
    for (int y = 2; y < m.height - 2; ++y) {
      for (int x = 2; x < m.width - 2; ++x) {
        const std::size_t i = m.At(x, y);
        if (!m.valid[i]) continue;
        const RegularizedPixel simd = RegularizePixelSimd(m.in, i);
        const RegularizedPixel scalar = RegularizePixelScalar(m.in, i);
        ASSERT_TRUE(SameBits(simd, scalar)) << "pixel " << x << "," << y;
        const RegularizedPixel ref = Reference(m, x, y);
        EXPECT_NEAR(simd.idepth, ref.idepth, 1e-5f * ref.idepth);
        EXPECT_NEAR(simd.variance, ref.variance, 1e-5f * ref.variance);
        EXPECT_NEAR(simd.support, ref.support, 1e-4f);
        EXPECT_NEAR(simd.agree, ref.agree, 1e-4f);
        EXPECT_NEAR(simd.disagree, ref.disagree, 1e-4f);
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 2000);
}

}  // namespace
}  // namespace parallax
