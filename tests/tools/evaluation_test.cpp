// Evaluation: association, Umeyama alignment, ATE against an independent implementation
// (Horn's quaternion method), RPE and degenerate input.

#include "tools/eval/evaluation.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <random>

#include "tools/eval/alignment.hpp"
#include "tools/eval/association.hpp"

namespace parallax {
namespace {

// Horn (1987) closed-form absolute orientation with unit quaternions, plus Horn's symmetric
// scale; written independently of AlignUmeyama (no SVD). Returns ATE RMSE after alignment.
double HornAteRmse(const std::vector<Eigen::Vector3d>& x, const std::vector<Eigen::Vector3d>& y,
                   bool with_scale) {
  const auto n = static_cast<double>(x.size());
  Eigen::Vector3d cx = Eigen::Vector3d::Zero(), cy = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < x.size(); ++i) {
    cx += x[i] / n;
    cy += y[i] / n;
  }
  Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
  double sxx = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    M += (x[i] - cx) * (y[i] - cy).transpose();
    sxx += (x[i] - cx).squaredNorm();
  }
  const double Sxx = M(0, 0), Sxy = M(0, 1), Sxz = M(0, 2), Syx = M(1, 0), Syy = M(1, 1),
               Syz = M(1, 2), Szx = M(2, 0), Szy = M(2, 1), Szz = M(2, 2);
  Eigen::Matrix4d N;
  N << Sxx + Syy + Szz, Syz - Szy, Szx - Sxz, Sxy - Syx,  //
      Syz - Szy, Sxx - Syy - Szz, Sxy + Syx, Szx + Sxz,   //
      Szx - Sxz, Sxy + Syx, -Sxx + Syy - Szz, Syz + Szy,  //
      Sxy - Syx, Szx + Sxz, Syz + Szy, -Sxx - Syy + Szz;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> eig(N);
  const Eigen::Vector4d q = eig.eigenvectors().col(3);
  const Eigen::Matrix3d R = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).toRotationMatrix();
  double s = 1.0;
  if (with_scale) {
    double num = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) num += (y[i] - cy).dot(R * (x[i] - cx));
    s = num / sxx;
  }
  double sum = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i)
    sum += (y[i] - (s * R * (x[i] - cx) + cy)).squaredNorm();
  return std::sqrt(sum / n);
}

struct Pair {
  Trajectory estimate;
  Trajectory groundtruth;
};

// Ground truth: a wobbly 3-D curve at 100 Hz; estimate at 30 Hz = S^-1 * gt + noise.
Pair MakePair(const Sim3d& S_gt_est, double noise, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, noise);
  Pair p;
  for (int i = 0; i < 300; ++i) {
    const double t = 100.0 + 0.01 * i;
    const Eigen::Vector3d pos(std::sin(t), 0.5 * std::cos(1.3 * t), 0.2 * t);
    p.groundtruth.push_back({t, SE3d(SO3d::Exp(Eigen::Vector3d(0.1 * t, 0.2, 0.0)), pos)});
  }
  const Sim3d S_est_gt = S_gt_est.Inverse();
  for (int i = 0; i < 90; ++i) {
    const double t = 100.0 + 0.0333 * i + 0.002;
    const StampedPose& g = p.groundtruth[static_cast<std::size_t>(std::lround((t - 100.0) / 0.01))];
    const Eigen::Vector3d pos =
        S_est_gt * g.T_w_c.Translation() + Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng));
    p.estimate.push_back({t, SE3d(S_est_gt.Rotation() * g.T_w_c.Rotation(), pos)});
  }
  return p;
}

TEST(Association, GreedyOneToOneBySmallestGap) {
  const auto at = [](const std::vector<double>& ts) {
    Trajectory t;
    for (const double s : ts) t.push_back({s, SE3d()});
    return t;
  };
  // 1.00 could match 1.005 or 0.99; 1.01 also wants 1.005 and is closer, so 1.00 gets 0.99.
  const auto pairs = AssociateByTimestamp(at({1.00, 1.011}), at({0.99, 1.008, 1.5}), 0.02);
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_EQ(pairs[0].groundtruth_index, 0u);
  EXPECT_EQ(pairs[1].groundtruth_index, 1u);
  EXPECT_TRUE(AssociateByTimestamp(at({5.0}), at({5.03}), 0.02).empty());
}

TEST(Evaluation, RecoversKnownSimilarityExactly) {
  const Sim3d S(2.5, SO3d::Exp(Eigen::Vector3d(0.3, -1.0, 0.4)), Eigen::Vector3d(1, -2, 0.5));
  const Pair p = MakePair(S, 0.0, 1);
  const EvaluationReport r = Evaluate(p.estimate, p.groundtruth, {});
  EXPECT_EQ(r.matched, 90u);
  EXPECT_NEAR(r.S_gt_est.Scale(), 2.5, 1e-9);
  EXPECT_LT(r.ate.rmse, 1e-9);
  EXPECT_LT(r.rpe_per_frame.rotation_deg.rmse, 1e-6);
  EXPECT_GT(r.coverage, 0.25);  // 90 estimates in a 3 s span of 100 Hz ground truth
}

TEST(Evaluation, AgreesWithIndependentHornImplementation) {
  const Sim3d S(0.7, SO3d::Exp(Eigen::Vector3d(-0.5, 0.2, 2.0)), Eigen::Vector3d(0.3, 0.1, -4));
  const Pair p = MakePair(S, 0.01, 2);
  const auto pairs = AssociateByTimestamp(p.estimate, p.groundtruth, 0.02);
  std::vector<Eigen::Vector3d> x, y;
  for (const auto& a : pairs) {
    x.push_back(p.estimate[a.estimate_index].T_w_c.Translation());
    y.push_back(p.groundtruth[a.groundtruth_index].T_w_c.Translation());
  }
  for (const bool scale : {true, false}) {
    EvaluationOptions options;
    options.alignment = scale ? AlignmentMode::kSim3 : AlignmentMode::kSE3;
    const EvaluationReport r = Evaluate(p.estimate, p.groundtruth, options);
    EXPECT_NEAR(r.ate.rmse, HornAteRmse(x, y, scale), 1e-4) << (scale ? "sim3" : "se3");
  }
  // Noise of 0.01 per axis in estimate units, scaled by 0.7: RMSE ~ 0.7 * 0.01 * sqrt(3).
  const EvaluationReport r = Evaluate(p.estimate, p.groundtruth, {});
  EXPECT_NEAR(r.ate.rmse, 0.7 * 0.01 * std::sqrt(3.0), 0.004);
  // Without scale the 0.7 mismatch dominates.
  EvaluationOptions se3;
  se3.alignment = AlignmentMode::kSE3;
  EXPECT_GT(Evaluate(p.estimate, p.groundtruth, se3).ate.rmse, 5.0 * r.ate.rmse);
}

TEST(Evaluation, DegenerateInputsGiveClearErrors) {
  Pair p = MakePair(Sim3d(), 0.0, 3);
  Trajectory two(p.estimate.begin(), p.estimate.begin() + 2);
  try {
    Evaluate(two, p.groundtruth, {});
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("only 2 pose(s) associate"), std::string::npos)
        << e.what();
  }
  Trajectory line_gt, line_est;
  for (int i = 0; i < 10; ++i) {
    line_gt.push_back({1.0 * i, SE3d(SO3d(), Eigen::Vector3d(0.1 * i, 0, 0))});
    line_est.push_back({1.0 * i, SE3d(SO3d(), Eigen::Vector3d(0, 0.2 * i, 0))});
  }
  // Positions alone cannot fix the turn about a straight line.
  std::vector<Eigen::Vector3d> line_x, line_y;
  for (std::size_t i = 0; i < line_gt.size(); ++i) {
    line_x.push_back(line_est[i].T_w_c.Translation());
    line_y.push_back(line_gt[i].T_w_c.Translation());
  }
  try {
    AlignUmeyama(line_x, line_y, AlignmentMode::kSim3);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("collinear"), std::string::npos) << e.what();
  }
  // All estimate positions equal: nothing to align, even with orientations.
  Trajectory still(line_est.size(), line_est.front());
  for (std::size_t i = 0; i < still.size(); ++i) still[i].timestamp = line_est[i].timestamp;
  EXPECT_THROW(Evaluate(still, line_gt, {}), std::invalid_argument);
  // Without alignment a straight line is fine.
  EvaluationOptions none;
  none.alignment = AlignmentMode::kNone;
  EXPECT_NEAR(Evaluate(line_est, line_gt, none).ate.max, std::hypot(0.9, 1.8), 1e-12);
}

TEST(Evaluation, TheWorstPoseIsNamedWithItsShareOfThePath) {
  // One pose of an exact trajectory pushed off by 0.2 m: without alignment it is the worst,
  // at its own time, and its error is measured against the matched ground-truth path.
  const Pair p = MakePair(Sim3d(), 0.0, 1);
  Trajectory estimate = p.estimate;
  estimate[40].T_w_c = SE3d(estimate[40].T_w_c.Rotation(),
                            estimate[40].T_w_c.Translation() + Eigen::Vector3d(0.2, 0, 0));
  EvaluationOptions none;
  none.alignment = AlignmentMode::kNone;
  const EvaluationReport r = Evaluate(estimate, p.groundtruth, none);
  EXPECT_NEAR(r.ate.max, 0.2, 1e-9);
  EXPECT_DOUBLE_EQ(r.ate_max_timestamp, estimate[40].timestamp);
  EXPECT_NEAR(r.ate_max_percent_of_path, 100.0 * 0.2 / r.groundtruth_path_length, 1e-9);
  EXPECT_NE(FormatReport(r).find("worst pose"), std::string::npos);
  EXPECT_NE(ReportToJson(r).find("ate_max_percent_of_path"), std::string::npos);
}

TEST(Evaluation, StraightTrajectoryIsAlignedWithTheOrientations) {
  // A camera sliding along a line while it turns (the rendered "rotate" motion): the
  // positions fix scale, translation and the line; the orientations fix the turn about it.
  const Sim3d S_gt_est(1.7, SO3d::Exp(Eigen::Vector3d(0.3, -0.5, 0.8)),
                       Eigen::Vector3d(1.0, -2.0, 0.5));
  Trajectory est, gt;
  for (int i = 0; i < 30; ++i) {
    const SE3d T_w_c(SO3d::Exp(Eigen::Vector3d(0.0, 0.02 * i, 0.01 * std::sin(0.3 * i))),
                     Eigen::Vector3d(0.05 * i, 0.0, 0.0));
    est.push_back({0.1 * i, T_w_c});
    const Sim3d S_w_c = S_gt_est * Sim3d(T_w_c);
    gt.push_back({0.1 * i, S_w_c.RigidPart()});
  }
  const EvaluationReport r = Evaluate(est, gt, {});
  EXPECT_LT(r.ate.max, 1e-9);
  EXPECT_NEAR(r.S_gt_est.Scale(), 1.7, 1e-9);
  EXPECT_LT((r.S_gt_est.Rotation().Inverse() * S_gt_est.Rotation()).Log().norm(), 1e-9);
}

TEST(Evaluation, KittiSegmentsOnLongPath) {
  Trajectory gt, est;
  for (int i = 0; i < 400; ++i) {
    const double t = 0.1 * i;
    gt.push_back({t, SE3d(SO3d(), Eigen::Vector3d(0, 0.01 * std::sin(t), 1.0 * i))});
    // 1% scale drift: each 100 m segment is 1 m too long.
    est.push_back({t, SE3d(SO3d(), Eigen::Vector3d(0, 0.01 * std::sin(t), 1.01 * i))});
  }
  EvaluationOptions none;
  none.alignment = AlignmentMode::kNone;
  const EvaluationReport r = Evaluate(est, gt, none);
  ASSERT_FALSE(r.kitti.empty());
  EXPECT_EQ(r.kitti.front().length, 100.0);
  EXPECT_NEAR(r.kitti.front().translation_percent, 1.0, 0.02);
  EXPECT_NEAR(r.rpe_per_frame.translation.mean, 0.01, 1e-3);
}

TEST(Evaluation, LocalScaleShowsScaleDriftThatSim3AlignmentHides) {
  // A 100 m drive whose second half is estimated 30% too long: one global scale cannot fit
  // both halves, and the per-distance pairs show the two local scales.
  Trajectory gt, est;
  double x_est = 0.0;
  for (int i = 0; i <= 100; ++i) {
    gt.push_back({0.1 * i, SE3d(SO3d(), Eigen::Vector3d(0.0, 0.05 * std::sin(0.2 * i), i))});
    if (i > 0) x_est += i <= 50 ? 1.0 : 1.3;
    est.push_back({0.1 * i, SE3d(SO3d(), Eigen::Vector3d(0.0, 0.05 * std::sin(0.2 * i), x_est))});
  }
  EvaluationOptions options;
  options.rpe_delta_meters = 10.0;
  const EvaluationReport drift = Evaluate(est, gt, options);
  ASSERT_GT(drift.local_scale.count, 80u);
  // Aligned scale s: the halves come out as s and 1.3 s, whatever s is.
  EXPECT_NEAR(drift.local_scale.max_ratio / drift.local_scale.min_ratio, 1.3, 0.01);
  EXPECT_GT(drift.local_scale.log_rmse, 0.1);
  const EvaluationReport exact = Evaluate(gt, gt, options);
  EXPECT_NEAR(exact.local_scale.min_ratio, 1.0, 1e-9);
  EXPECT_NEAR(exact.local_scale.max_ratio, 1.0, 1e-9);
  EXPECT_LT(exact.local_scale.log_rmse, 1e-9);
}

}  // namespace
}  // namespace parallax
