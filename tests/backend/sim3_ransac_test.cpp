// Sim(3) RANSAC on 3-D point matches: recovers a known similarity among outliers, refuses
// pure outliers, deterministic; the shared Umeyama fit.

#include "backend/sim3_ransac.hpp"

#include <gtest/gtest.h>

#include <random>

#include "core/similarity_fit.hpp"

namespace parallax {
namespace {

PinholeCamera Camera() { return PinholeCamera(640, 480, 500.0, 500.0, 319.5, 239.5); }

/// Points in front of camera b, seen by camera a through S_a_b; `outliers` of them are
/// replaced in a by random points in view.
std::vector<PointMatch3d> Matches(const Sim3d& S_a_b, int n, int outliers, std::uint64_t seed) {
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<PointMatch3d> matches;
  while (static_cast<int>(matches.size()) < n) {
    PointMatch3d m;
    m.px_b = Eigen::Vector2d(20 + 600 * u(random), 20 + 440 * u(random));
    m.p_b = Camera().Unproject(m.px_b) * (1.0 + 3.0 * u(random));
    m.p_a = S_a_b * m.p_b;
    if (m.p_a.z() < 0.1) continue;
    m.px_a = Camera().Project(m.p_a);
    if (m.px_a.x() < 0 || m.px_a.y() < 0 || m.px_a.x() > 639 || m.px_a.y() > 479) continue;
    if (static_cast<int>(matches.size()) < outliers) {
      m.px_a = Eigen::Vector2d(20 + 600 * u(random), 20 + 440 * u(random));
      m.p_a = Camera().Unproject(m.px_a) * (1.0 + 3.0 * u(random)) * S_a_b.Scale();
    }
    matches.push_back(m);
  }
  return matches;
}

Sim3d Truth() {
  return Sim3d(1.7, SO3d::Exp(Eigen::Vector3d(0.05, -0.2, 0.03)), Eigen::Vector3d(0.3, -0.1, 0.2));
}

TEST(Sim3Ransac, FindsTheSimilarityAmongFortyPercentOutliers) {
  const auto matches = Matches(Truth(), 100, 40, 1);
  const Sim3RansacResult r = EstimateSim3Ransac(matches, Camera(), {});
  ASSERT_TRUE(r.found);
  EXPECT_NEAR(r.S_a_b.Scale(), Truth().Scale(), 1e-9);
  EXPECT_LT((r.S_a_b.Translation() - Truth().Translation()).norm(), 1e-9);
  EXPECT_LT((r.S_a_b.Rotation().Inverse() * Truth().Rotation()).Log().norm(), 1e-9);
  // Exactly the 60 true matches (an outlier landing on its true position is unlikely).
  EXPECT_GE(r.inliers.size(), 60u);
  EXPECT_LE(r.inliers.size(), 62u);
  for (const std::uint32_t i : r.inliers) EXPECT_GE(i, 38u);
  const Sim3RansacResult again = EstimateSim3Ransac(matches, Camera(), {});
  EXPECT_EQ(again.inliers, r.inliers);
  EXPECT_EQ(again.iterations, r.iterations);
}

TEST(Sim3Ransac, RefusesMatchesWithoutACommonSimilarity) {
  const auto matches = Matches(Truth(), 100, 100, 2);
  EXPECT_FALSE(EstimateSim3Ransac(matches, Camera(), {}).found);
  EXPECT_FALSE(EstimateSim3Ransac({}, Camera(), {}).found);
  Sim3RansacOptions bad;
  bad.min_inliers = 2;
  EXPECT_THROW(EstimateSim3Ransac(matches, Camera(), bad), std::invalid_argument);
}

TEST(SimilarityFit, RecoversAnExactSimilarityAndRejectsDegenerateSets) {
  std::vector<Eigen::Vector3d> x = {{0, 0, 1}, {1, 0, 2}, {0, 1, 3}, {1, 1, 1.5}};
  std::vector<Eigen::Vector3d> y;
  y.reserve(x.size());
  for (const auto& p : x) y.push_back(Truth() * p);
  const auto S = FitSimilarity(x, y, true);
  ASSERT_TRUE(S.has_value());
  EXPECT_NEAR(S->Scale(), Truth().Scale(), 1e-12);
  EXPECT_LT((S->Translation() - Truth().Translation()).norm(), 1e-12);
  const auto rigid = FitSimilarity(x, y, false);
  ASSERT_TRUE(rigid.has_value());
  EXPECT_EQ(rigid->Scale(), 1.0);
  const std::vector<Eigen::Vector3d> line = {{0, 0, 1}, {1, 0, 1}, {2, 0, 1}};
  EXPECT_FALSE(FitSimilarity(line, line, true).has_value());
  EXPECT_FALSE(FitSimilarity(std::vector<Eigen::Vector3d>(x.begin(), x.begin() + 2),
                             std::vector<Eigen::Vector3d>(y.begin(), y.begin() + 2), true)
                   .has_value());
}

}  // namespace
}  // namespace parallax
