#include "tracking/photometric_batch.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "core/frame.hpp"
#include "core/se3.hpp"

namespace parallax {
namespace {

// A textured 160x120 frame (smooth sinusoids plus noise), so lookups and gradients vary.
std::shared_ptr<const Frame> TexturedFrame() {
  ImageU8 image(160, 120);
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> noise(-10, 10);
  for (int y = 0; y < 120; ++y) {
    for (int x = 0; x < 160; ++x) {
      const double value = 128.0 + 60.0 * std::sin(0.21 * x) * std::cos(0.17 * y) + noise(rng);
      image(x, y) = static_cast<std::uint8_t>(std::clamp(value, 0.0, 255.0));
    }
  }
  return std::make_shared<const Frame>(0, 0.0, PinholeCamera(160, 120, 120, 120, 79.5, 59.5), image,
                                       PyramidOptions{1, 8});
}

// Every lane of the SSE2 kernel equals EvaluatePhotometric + HuberWeight bit for bit: which
// points are in view, and every output for those that are, over random poses and points
// (some behind the camera, some outside the image).
TEST(PhotometricBatchTest, LanesEqualTheScalarKernelBitForBit) {
  const auto frame = TexturedFrame();
  const PyramidLevel& level = frame->Level(0);
  const LevelCamera camera = ToLevelCamera(frame->Camera(0));
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> ray(-1.0f, 1.0f), depth(0.05f, 2.0f), grey(0.0f, 255.0f);
  std::uniform_real_distribution<double> motion(-0.3, 0.3);
  int in_view = 0, out_of_view = 0;
  for (int trial = 0; trial < 200; ++trial) {
    Eigen::Matrix<double, 6, 1> xi;
    for (int j = 0; j < 6; ++j) xi[j] = motion(rng);
    const SE3d T = SE3d::Exp(xi);
    PhotometricModel model;
    model.M = T.RotationMatrix().cast<float>();
    model.t = T.Translation().cast<float>();
    model.gain = 0.8f + 0.01f * static_cast<float>(trial % 40);
    model.offset = -5.0f + 0.1f * static_cast<float>(trial % 100);
    model.pixel_noise_variance = 16.0f;
    model.huber_k = 1.5f;
    std::array<float, 8> rx{}, ry{}, d{}, var{}, ref{};
    for (std::size_t i = 0; i < 8; ++i) {
      rx[i] = ray(rng);
      ry[i] = 0.75f * ray(rng);
      d[i] = depth(rng);
      var[i] = 1e-3f * d[i] * d[i] * static_cast<float>(1 + i);
      ref[i] = grey(rng);
    }
    const PhotometricPoints points{rx.data(), ry.data(), d.data(), var.data(), ref.data()};
    for (std::size_t first : {std::size_t{0}, std::size_t{4}}) {
      PhotometricBatch batch;
      EvaluatePhotometric4(level, camera, model, points, first, &batch);
      for (std::size_t lane = 0; lane < 4; ++lane) {
        const std::size_t i = first + lane;
        PhotometricTerm term;
        const bool scalar_in_view =
            EvaluatePhotometric(level, camera, model.M, model.t, rx[i], ry[i], d[i], var[i], ref[i],
                                model.gain, model.offset, model.pixel_noise_variance, &term);
        ASSERT_EQ((batch.in_view >> lane) & 1u, scalar_in_view ? 1u : 0u) << trial << " " << i;
        if (!scalar_in_view) {
          ++out_of_view;
          continue;
        }
        ++in_view;
        const RobustWeight w = HuberWeight(term.residual, term.variance, model.huber_k);
        for (int r = 0; r < 3; ++r) {
          EXPECT_EQ(batch.dr_dp[r][lane], term.dr_dp[r]) << trial << " " << i << " dr_dp " << r;
          EXPECT_EQ(batch.p[r][lane], term.p[r]) << trial << " " << i << " p " << r;
        }
        EXPECT_EQ(batch.residual[lane], term.residual) << trial << " " << i;
        EXPECT_EQ(batch.variance[lane], term.variance) << trial << " " << i;
        EXPECT_EQ(batch.gradient_sq[lane], term.gradient_sq) << trial << " " << i;
        EXPECT_EQ(batch.weight[lane], w.weight) << trial << " " << i;
        EXPECT_EQ(batch.cost[lane], w.cost) << trial << " " << i;
      }
    }
  }
  // Both branches were exercised.
  EXPECT_GT(in_view, 400);
  EXPECT_GT(out_of_view, 100);
}

}  // namespace
}  // namespace parallax
