// RefineRelativePose on synthetic correspondences with known relative pose.

#include "backend/relative_pose_refinement.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <random>

#include "core/angles.hpp"

namespace parallax {
namespace {

constexpr double kFocal = 500.0;

struct Correspondences {
  std::vector<Eigen::Vector2d> ref, cur;
};

// Points 2-8 m in front of the reference seen from both views; pixel noise sigma `noise_px`.
Correspondences Make(const RelativePose& truth, int n, double noise_px, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uv(-0.5, 0.5), depth(2.0, 8.0);
  std::normal_distribution<double> noise(0.0, noise_px / kFocal);
  Correspondences c;
  while (static_cast<int>(c.ref.size()) < n) {
    const Eigen::Vector3d X = Eigen::Vector3d(uv(rng), uv(rng), 1.0) * depth(rng);
    const Eigen::Vector3d Y = truth.R_cur_ref * X + 0.3 * truth.t_cur_ref;
    if (Y.z() <= 0.1) continue;
    c.ref.emplace_back(X.x() / X.z() + noise(rng), X.y() / X.z() + noise(rng));
    c.cur.emplace_back(Y.x() / Y.z() + noise(rng), Y.y() / Y.z() + noise(rng));
  }
  return c;
}

RelativePose Truth() {
  return {SO3d::Exp(Eigen::Vector3d(0.01, 0.05, -0.02)),
          Eigen::Vector3d(0.8, 0.1, 0.3).normalized()};
}

TEST(SampsonDistance, ZeroOnTheConstraintAndPixelLikeOffIt) {
  const RelativePose truth = Truth();
  const Correspondences c = Make(truth, 20, 0.0, 1);
  const Eigen::Matrix3d E = SO3d::Hat(truth.t_cur_ref) * truth.R_cur_ref.Matrix();
  for (std::size_t i = 0; i < c.ref.size(); ++i) {
    EXPECT_NEAR(SampsonDistance(E, c.ref[i], c.cur[i]), 0.0, 1e-12);
    // Moving the current point by d along its epipolar line's normal changes the distance by
    // about d / sqrt(2) (the Sampson distance splits the error between both views).
    const Eigen::Vector3d line = E * c.ref[i].homogeneous();
    const Eigen::Vector2d normal = line.head<2>().normalized();
    const double d = 2.0 / kFocal;
    const double moved = std::abs(SampsonDistance(E, c.ref[i], c.cur[i] + d * normal));
    EXPECT_GT(moved, 0.3 * d);
    EXPECT_LT(moved, 1.01 * d);
  }
}

TEST(RefineRelativePose, ConvergesFromAPerturbedPoseToTheTruth) {
  const RelativePose truth = Truth();
  const Correspondences c = Make(truth, 300, 0.5, 2);
  RelativePose start;
  start.R_cur_ref =
      SO3d::Exp(Eigen::Vector3d(0.0, 2.0 / kRadToDeg, 1.0 / kRadToDeg)) * truth.R_cur_ref;
  start.t_cur_ref = (SO3d::Exp(Eigen::Vector3d(0.0, 0.0, 8.0 / kRadToDeg)) * truth.t_cur_ref);
  const RelativePose refined = RefineRelativePose(c.ref, c.cur, start, kFocal);
  EXPECT_LT((refined.R_cur_ref.Inverse() * truth.R_cur_ref).Log().norm() * kRadToDeg, 0.1);
  EXPECT_LT(AngleBetweenDeg(refined.t_cur_ref, truth.t_cur_ref), 0.5);
  EXPECT_NEAR(refined.t_cur_ref.norm(), 1.0, 1e-12);
}

// The refinement runs on RANSAC's inliers; Huber weights still bound what a few wrong matches
// (5% here, far off their epipolar lines) can do compared with plain least squares.
TEST(RefineRelativePose, OutliersPullLessThanInLeastSquares) {
  const RelativePose truth = Truth();
  Correspondences c = Make(truth, 300, 0.5, 3);
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> uv(-0.5, 0.5);
  for (std::size_t i = 0; i < c.cur.size(); i += 20) c.cur[i] = {uv(rng), uv(rng)};
  RelativePoseRefinementOptions least_squares;
  least_squares.huber_px = 1e6;
  const double robust =
      AngleBetweenDeg(RefineRelativePose(c.ref, c.cur, truth, kFocal).t_cur_ref, truth.t_cur_ref);
  const double plain = AngleBetweenDeg(
      RefineRelativePose(c.ref, c.cur, truth, kFocal, least_squares).t_cur_ref, truth.t_cur_ref);
  RecordProperty("robust_deg", std::to_string(robust));
  RecordProperty("least_squares_deg", std::to_string(plain));
  EXPECT_LT(robust, 2.0);  // measured 1.4 degrees; least squares 72
  EXPECT_LT(robust, 0.5 * plain);
}

TEST(RefineRelativePose, TooFewPointsReturnTheStart) {
  const RelativePose truth = Truth();
  const Correspondences c = Make(truth, 4, 0.0, 5);
  RelativePose start = truth;
  start.t_cur_ref = Eigen::Vector3d::UnitX();
  EXPECT_EQ(RefineRelativePose(c.ref, c.cur, start, kFocal).t_cur_ref, start.t_cur_ref);
  EXPECT_THROW(RefineRelativePose(c.ref, {}, start, kFocal), std::invalid_argument);
  RelativePoseRefinementOptions bad;
  bad.huber_px = 0.0;
  EXPECT_THROW(bad.Check(), std::invalid_argument);
}

// The predicted covariance against the spread of the refined poses over noise draws, on a
// sideways step with a turn (the ambiguous case: the rotation's worst axis is the turn
// coupled with the step).
TEST(RelativePoseCovariance, MatchesTheSpreadOverNoiseDraws) {
  const RelativePose truth{SO3d::Exp(Eigen::Vector3d(0.0, 0.04, 0.0)),
                           Eigen::Vector3d(1.0, 0.0, 0.1).normalized()};
  constexpr int kDraws = 150;
  constexpr double kNoisePx = 0.5;
  Eigen::Matrix3d spread = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d predicted = Eigen::Matrix3d::Zero();
  for (int draw = 0; draw < kDraws; ++draw) {
    const Correspondences c = Make(truth, 200, kNoisePx, 100 + static_cast<std::uint32_t>(draw));
    const RelativePose refined = RefineRelativePose(c.ref, c.cur, truth, kFocal);
    const Eigen::Vector3d error = (refined.R_cur_ref * truth.R_cur_ref.Inverse()).Log();
    spread += error * error.transpose() / kDraws;
    predicted +=
        RelativePoseCovariance(c.ref, c.cur, refined, kFocal, 1.0).topLeftCorner<3, 3>() / kDraws;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(predicted);
  const Eigen::Vector3d worst = eigen.eigenvectors().col(2);
  const double predicted_deg = std::sqrt(eigen.eigenvalues()[2]) * kRadToDeg;
  const double measured_deg = std::sqrt(worst.dot(spread * worst)) * kRadToDeg;
  RecordProperty("predicted_deg", std::to_string(predicted_deg));
  RecordProperty("measured_deg", std::to_string(measured_deg));
  EXPECT_GT(measured_deg, 0.75 * predicted_deg);
  EXPECT_LT(measured_deg, 1.33 * predicted_deg);
  // The turn about the vertical axis, coupled with the sideways step, is the worst axis.
  EXPECT_GT(std::abs(worst.y()), 0.9);
  // A 20 times smaller noise predicts a 20 times smaller spread.
  const Correspondences quiet = Make(truth, 200, kNoisePx / 20.0, 7);
  const double quiet_deg =
      std::sqrt(RelativePoseCovariance(quiet.ref, quiet.cur, truth, kFocal, 1.0)
                    .topLeftCorner<3, 3>()
                    .eigenvalues()
                    .real()
                    .maxCoeff()) *
      kRadToDeg;
  EXPECT_NEAR(quiet_deg, predicted_deg / 20.0, 0.3 * predicted_deg / 20.0);
  EXPECT_THROW(RelativePoseCovariance(quiet.ref, {}, truth, kFocal, 1.0), std::invalid_argument);
}

}  // namespace
}  // namespace parallax
