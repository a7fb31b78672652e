#include "tracking/photometric_batch.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <random>
#include <vector>

#include "core/frame.hpp"
#include "core/se3.hpp"
#include "tracking/photometric_lane_sums.hpp"

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

std::uint32_t Bits(float x) {
  std::uint32_t bits = 0;
  std::memcpy(&bits, &x, sizeof(bits));
  return bits;
}

std::uint64_t Bits(double x) {
  std::uint64_t bits = 0;
  std::memcpy(&bits, &x, sizeof(bits));
  return bits;
}

// Eight random points and a random warp: some points behind the camera, some outside the
// image.
struct RandomTrial {
  PhotometricModel model;
  std::array<float, 8> rx{}, ry{}, d{}, var{}, ref{};
  PhotometricPoints Points() const {
    return {rx.data(), ry.data(), d.data(), var.data(), ref.data()};
  }
};

RandomTrial MakeTrial(int trial, std::mt19937* rng) {
  std::uniform_real_distribution<float> ray(-1.0f, 1.0f), depth(0.05f, 2.0f), grey(0.0f, 255.0f);
  std::uniform_real_distribution<double> motion(-0.3, 0.3);
  Eigen::Matrix<double, 6, 1> xi;
  for (int j = 0; j < 6; ++j) xi[j] = motion(*rng);
  const SE3d T = SE3d::Exp(xi);
  RandomTrial t;
  t.model.M = T.RotationMatrix().cast<float>();
  t.model.t = T.Translation().cast<float>();
  t.model.gain = 0.8f + 0.01f * static_cast<float>(trial % 40);
  t.model.offset = -5.0f + 0.1f * static_cast<float>(trial % 100);
  t.model.pixel_noise_variance = 16.0f;
  t.model.huber_k = 1.5f;
  for (std::size_t i = 0; i < 8; ++i) {
    t.rx[i] = ray(*rng);
    t.ry[i] = 0.75f * ray(*rng);
    t.d[i] = depth(*rng);
    t.var[i] = 1e-3f * t.d[i] * t.d[i] * static_cast<float>(1 + i);
    t.ref[i] = grey(*rng);
  }
  return t;
}

// Compares every lane of the SSE2 kernel with EvaluatePhotometric + HuberWeight over random
// poses and points; counts the lanes in and out of view.
void ExpectLanesEqualTheScalarKernel(const PyramidLevel& level, const LevelCamera& camera,
                                     std::uint32_t seed, int* in_view, int* out_of_view) {
  std::mt19937 rng(seed);
  for (int trial = 0; trial < 200; ++trial) {
    const RandomTrial t = MakeTrial(trial, &rng);
    const PhotometricModel& model = t.model;
    for (std::size_t first : {std::size_t{0}, std::size_t{4}}) {
      PhotometricBatch batch;
      EvaluatePhotometric4(level, camera, model, t.Points(), first, &batch);
      for (std::size_t lane = 0; lane < 4; ++lane) {
        const std::size_t i = first + lane;
        PhotometricTerm term;
        const bool scalar_in_view = EvaluatePhotometric(
            level, camera, model.M, model.t, t.rx[i], t.ry[i], t.d[i], t.var[i], t.ref[i],
            model.gain, model.offset, model.pixel_noise_variance, &term);
        ASSERT_EQ((batch.in_view >> lane) & 1u, scalar_in_view ? 1u : 0u) << trial << " " << i;
        if (!scalar_in_view) {
          ++*out_of_view;
          continue;
        }
        ++*in_view;
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
}

// Every lane of the SSE2 kernel equals EvaluatePhotometric + HuberWeight bit for bit: which
// points are in view, and every output for those that are, over random poses and points;
// also where a validity mask leaves a third of the frame without input.
TEST(PhotometricBatchTest, LanesEqualTheScalarKernelBitForBit) {
  const auto frame = TexturedFrame();
  const PyramidLevel& level = frame->Level(0);
  const LevelCamera camera = ToLevelCamera(frame->Camera(0));
  int in_view = 0, out_of_view = 0;
  ExpectLanesEqualTheScalarKernel(level, camera, 11, &in_view, &out_of_view);
  // Both branches were exercised.
  EXPECT_GT(in_view, 400);
  EXPECT_GT(out_of_view, 100);
  std::vector<std::uint8_t> valid(static_cast<std::size_t>(level.Width() * level.Height()));
  std::mt19937 rng(2);
  for (std::uint8_t& v : valid) v = rng() % 3 == 0 ? 0 : 1;
  PyramidLevel masked = level;
  masked.valid = valid.data();
  int masked_in_view = 0, masked_out_of_view = 0;
  ExpectLanesEqualTheScalarKernel(masked, camera, 11, &masked_in_view, &masked_out_of_view);
  EXPECT_EQ(masked_in_view + masked_out_of_view, in_view + out_of_view);
  EXPECT_LT(masked_in_view, 0.8 * in_view);
  EXPECT_GT(masked_in_view, 0.5 * in_view);
}

// The SSE2 lane sums equal their scalar twin bit for bit, lanes out of view included (their
// entries are made NaN here: they must add nothing), and the reduced sums are the normal
// equations of the Jacobian [dr/dp, p x dr/dp, -gain I_ref, -1] summed point by point.
TEST(PhotometricBatchTest, LaneSumsEqualTheScalarTwinAndThePointByPointEquations) {
  const auto frame = TexturedFrame();
  const PyramidLevel& level = frame->Level(0);
  const LevelCamera camera = ToLevelCamera(frame->Camera(0));
  std::mt19937 rng(5);
  const float good_sq = 9.0f;
  Se3LaneSums simd, scalar;
  NormalEquations<8> expected;
  int expected_good = 0;
  double expected_sq_residual = 0.0, expected_gradient_sq = 0.0;
  for (int trial = 0; trial < 300; ++trial) {
    const RandomTrial t = MakeTrial(trial, &rng);
    for (std::size_t first : {std::size_t{0}, std::size_t{4}}) {
      PhotometricBatch batch;
      EvaluatePhotometric4(level, camera, t.model, t.Points(), first, &batch);
      for (int lane = 0; lane < 4; ++lane) {
        if ((batch.in_view & (1u << lane)) != 0) continue;
        for (int r = 0; r < 3; ++r) batch.dr_dp[r][lane] = batch.p[r][lane] = std::nanf("");
        batch.residual[lane] = batch.weight[lane] = batch.cost[lane] = std::nanf("");
      }
      AddSe3Batch(batch, t.ref.data() + first, t.model.gain, good_sq, &simd);
      AddSe3BatchScalar(batch, t.ref.data() + first, t.model.gain, good_sq, &scalar);
      for (std::size_t lane = 0; lane < 4; ++lane) {
        if ((batch.in_view & (1u << lane)) == 0) continue;
        const Eigen::Vector3d dr_dp(batch.dr_dp[0][lane], batch.dr_dp[1][lane],
                                    batch.dr_dp[2][lane]);
        const Eigen::Vector3d p(batch.p[0][lane], batch.p[1][lane], batch.p[2][lane]);
        Eigen::Matrix<float, 8, 1> J;
        J << dr_dp.cast<float>(), p.cross(dr_dp).cast<float>(), -t.model.gain * t.ref[first + lane],
            -1.0f;
        const float r = batch.residual[lane];
        expected.Add(J, r, batch.weight[lane], batch.cost[lane]);
        expected_good += r * r < good_sq * batch.variance[lane] ? 1 : 0;
        expected_sq_residual += static_cast<double>(r) * r;
        expected_gradient_sq += batch.gradient_sq[lane];
      }
    }
  }
  // Bit for bit (a float comparison would take -0 for +0 and fail on NaN).
  const auto expect_same_bits = [](const auto& a, const auto& b) {
    for (int k = 0; k < 4; ++k) EXPECT_EQ(Bits(a[k]), Bits(b[k])) << k;
  };
  for (int k = 0; k < Se3LaneSums::kEntries; ++k) expect_same_bits(simd.H[k], scalar.H[k]);
  for (int k = 0; k < 8; ++k) expect_same_bits(simd.g[k], scalar.g[k]);
  expect_same_bits(simd.cost, scalar.cost);
  expect_same_bits(simd.sum_sq_residual, scalar.sum_sq_residual);
  expect_same_bits(simd.sum_gradient_sq, scalar.sum_gradient_sq);
  EXPECT_EQ(simd.in_view, scalar.in_view);
  EXPECT_EQ(simd.good, scalar.good);
  NormalEquations<8> reduced;
  int in_view = 0, good = 0;
  double sq_residual = 0.0, gradient_sq = 0.0;
  ReduceLaneSums(simd, &reduced, &in_view, &good, &sq_residual, &gradient_sq);
  ASSERT_GT(in_view, 600);
  EXPECT_EQ(in_view, expected.count);
  EXPECT_EQ(reduced.count, expected.count);
  EXPECT_EQ(good, expected_good);
  EXPECT_NEAR(sq_residual, expected_sq_residual, 1e-9 * expected_sq_residual);
  EXPECT_NEAR(gradient_sq, expected_gradient_sq, 1e-9 * expected_gradient_sq);
  // Float sums in another order: equal to a few parts in a million.
  const auto H = reduced.SymmetricH(), H_expected = expected.SymmetricH();
  EXPECT_LT((H - H_expected).norm(), 1e-5 * H_expected.norm());
  EXPECT_LT((reduced.g - expected.g).norm(), 1e-5 * expected.g.norm());
  EXPECT_NEAR(reduced.cost, expected.cost, 1e-5 * expected.cost);
}

// The last one to three points of a level, evaluated on a padded copy: the lanes that exist
// equal the full kernel's, the others are out of view.
TEST(PhotometricBatchTest, TailEqualsTheKernelOnItsLanes) {
  const auto frame = TexturedFrame();
  const PyramidLevel& level = frame->Level(0);
  const LevelCamera camera = ToLevelCamera(frame->Camera(0));
  std::mt19937 rng(7);
  int compared = 0;
  for (int trial = 0; trial < 100; ++trial) {
    const RandomTrial t = MakeTrial(trial, &rng);
    PhotometricBatch full;
    EvaluatePhotometric4(level, camera, t.model, t.Points(), 4, &full);
    for (std::size_t count = 1; count <= 3; ++count) {
      PhotometricBatch tail;
      float ref[4];
      EvaluatePhotometricTail(level, camera, t.model, t.Points(), 4, count, &tail, ref);
      EXPECT_EQ(tail.in_view, full.in_view & ((1u << count) - 1u)) << trial;
      for (std::size_t lane = 0; lane < count; ++lane) {
        EXPECT_EQ(ref[lane], t.ref[4 + lane]);
        if ((tail.in_view & (1u << lane)) == 0) continue;
        ++compared;
        EXPECT_EQ(tail.residual[lane], full.residual[lane]) << trial << " " << lane;
        EXPECT_EQ(tail.weight[lane], full.weight[lane]) << trial << " " << lane;
        for (int r = 0; r < 3; ++r) EXPECT_EQ(tail.dr_dp[r][lane], full.dr_dp[r][lane]);
      }
    }
  }
  EXPECT_GT(compared, 100);
}

}  // namespace
}  // namespace parallax
