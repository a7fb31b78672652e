// SE(3) tracker: Jacobians against numeric differentiation, convergence on renders with exact
// depth, the affine brightness model, lost detection, determinism.

#include "tracking/se3_tracker.hpp"

#include <gtest/gtest.h>

#include <numeric>

#include "tests/tracking/render_fixture.hpp"
#include "tests/tracking/room_shake_fixture.hpp"
#include "tracking/photometric_residual.hpp"

namespace parallax {
namespace {

using test::ComparePoses;

// --- Jacobians -------------------------------------------------------------------------

// Float planes of an analytic image, so that the kernel's gradient lookups are exact:
// I = c + ax x + ay y + q ((x - 300)^2 + (y - 200)^2). Central differences of a quadratic
// are exact at pixel centres and bilinear interpolation of the (linear) gradient is exact.
struct AnalyticLevel {
  ImageF intensity{640, 480}, dx{640, 480}, dy{640, 480};
  PyramidLevel level;
  explicit AnalyticLevel(double q) {
    for (int y = 0; y < 480; ++y) {
      for (int x = 0; x < 640; ++x) {
        const double ex = x - 300.0, ey = y - 200.0;
        intensity(x, y) = static_cast<float>(20.0 + 0.3 * x + 0.2 * y + q * (ex * ex + ey * ey));
        dx(x, y) = static_cast<float>(0.3 + 2.0 * q * ex);
        dy(x, y) = static_cast<float>(0.2 + 2.0 * q * ey);
      }
    }
    level = PyramidLevel{intensity, dx, dy};
  }
};

struct KernelInput {
  Eigen::Matrix3f M;
  Eigen::Vector3f t;
  float ray_x = 0.05f, ray_y = -0.08f, idepth = 0.4f, intensity = 90.0f, gain = 1.3f, offset = 4.0f;
};

double Residual(const PyramidLevel& level, const LevelCamera& cam, const KernelInput& in) {
  PhotometricTerm term;
  EXPECT_TRUE(EvaluatePhotometric(level, cam, in.M, in.t, in.ray_x, in.ray_y, in.idepth, 0.0f,
                                  in.intensity, in.gain, in.offset, 16.0f, &term));
  return term.residual;
}

KernelInput WithPose(KernelInput in, const SE3d& T) {
  in.M = T.RotationMatrix().cast<float>();
  in.t = T.Translation().cast<float>();
  return in;
}

class PhotometricJacobianTest : public ::testing::TestWithParam<double> {};

TEST_P(PhotometricJacobianTest, MatchesNumericDifferentiation) {
  const AnalyticLevel image(GetParam());
  const LevelCamera cam{525.0f, 525.0f, 319.5f, 239.5f, 638.0f, 478.0f};
  const SE3d T =
      SE3d::Exp((Eigen::Matrix<double, 6, 1>() << 0.1, -0.05, 0.2, 0.02, -0.03, 0.01).finished());
  const KernelInput in = WithPose(KernelInput{}, T);
  PhotometricTerm term;
  ASSERT_TRUE(EvaluatePhotometric(image.level, cam, in.M, in.t, in.ray_x, in.ray_y, in.idepth,
                                  0.01f, in.intensity, in.gain, in.offset, 16.0f, &term));
  Eigen::Matrix<double, 6, 1> J_analytic;
  J_analytic.head<3>() = term.dr_dp.cast<double>();
  J_analytic.tail<3>() = term.p.cross(term.dr_dp).cast<double>();
  ASSERT_GT(J_analytic.norm(), 10.0);  // not trivially zero
  const double h = 1e-3;
  for (int k = 0; k < 6; ++k) {
    Eigen::Matrix<double, 6, 1> d = Eigen::Matrix<double, 6, 1>::Zero();
    d[k] = h;
    const double numeric = (Residual(image.level, cam, WithPose(in, SE3d::Exp(d) * T)) -
                            Residual(image.level, cam, WithPose(in, SE3d::Exp(-d) * T))) /
                           (2 * h);
    EXPECT_NEAR(J_analytic[k], numeric, 0.01 * std::abs(numeric) + 0.05) << "pose parameter " << k;
  }
  // Sim(3) scale column: p = exp(sigma) (R P) + exp(sigma) t under a left scale increment,
  // so dr/dsigma = dr/dp . p.
  const double s = 1e-3;
  KernelInput scaled_up = in, scaled_down = in;
  scaled_up.M *= std::exp(static_cast<float>(s));
  scaled_up.t *= std::exp(static_cast<float>(s));
  scaled_down.M *= std::exp(static_cast<float>(-s));
  scaled_down.t *= std::exp(static_cast<float>(-s));
  const double numeric_scale =
      (Residual(image.level, cam, scaled_up) - Residual(image.level, cam, scaled_down)) / (2 * s);
  EXPECT_NEAR(term.dr_dp.dot(term.p), numeric_scale, 0.01 * std::abs(numeric_scale) + 0.05);
  // Affine terms: r = I - exp(a) I_ref - b, so dr/da = -exp(a) I_ref and dr/db = -1.
  KernelInput brighter = in;
  brighter.gain = in.gain * std::exp(1e-3f);
  EXPECT_NEAR((Residual(image.level, cam, brighter) - Residual(image.level, cam, in)) / 1e-3,
              -in.gain * in.intensity, 0.2);
  KernelInput shifted = in;
  shifted.offset += 0.5f;
  EXPECT_NEAR(Residual(image.level, cam, shifted) - Residual(image.level, cam, in), -0.5, 1e-4);
  // d r / d idepth enters the variance: variance - sigma_I^2 = (dr/dd)^2 var(idepth).
  KernelInput nearer = in, farther = in;
  nearer.idepth += 1e-3f;
  farther.idepth -= 1e-3f;
  const double dr_dd =
      (Residual(image.level, cam, nearer) - Residual(image.level, cam, farther)) / 2e-3;
  ASSERT_GT(std::abs(dr_dd), 1.0);
  EXPECT_NEAR(term.variance - 16.0, dr_dd * dr_dd * 0.01, 0.02 * dr_dd * dr_dd * 0.01);
}

INSTANTIATE_TEST_SUITE_P(RampAndQuadratic, PhotometricJacobianTest, ::testing::Values(0.0, 2e-4));

TEST(PhotometricKernel, APointWhereTheFrameSeesNoInputIsOutsideIt) {
  AnalyticLevel image(0.0);
  const LevelCamera cam{525.0f, 525.0f, 319.5f, 239.5f, 638.0f, 478.0f};
  const KernelInput in = WithPose(KernelInput{}, SE3d());
  PhotometricTerm term;
  ASSERT_TRUE(EvaluatePhotometric(image.level, cam, in.M, in.t, in.ray_x, in.ray_y, in.idepth, 0.0f,
                                  in.intensity, in.gain, in.offset, 16.0f, &term));
  // The point lands at (345.75, 197.5): its pixel masked out, it is not evaluated.
  ImageU8 valid(640, 480, 1);
  image.level.valid = valid.Data();
  EXPECT_TRUE(EvaluatePhotometric(image.level, cam, in.M, in.t, in.ray_x, in.ray_y, in.idepth, 0.0f,
                                  in.intensity, in.gain, in.offset, 16.0f, &term));
  valid(345, 197) = 0;
  EXPECT_FALSE(EvaluatePhotometric(image.level, cam, in.M, in.t, in.ray_x, in.ray_y, in.idepth,
                                   0.0f, in.intensity, in.gain, in.offset, 16.0f, &term));
}

// --- Convergence on renders ------------------------------------------------------------

class Se3TrackerRenderTest : public test::RoomShakeKeyframeTest {
 protected:
  // Perturbation: `degrees` about a fixed axis, translation `fraction` of the scene depth.
  static SE3d Perturb(const SE3d& T, double degrees, double fraction, int variant) {
    const Eigen::Vector3d axes[] = {{1, 0.3, -0.2}, {-0.4, 1, 0.5}, {0.2, -0.6, 1}, {1, 1, 1}};
    const Eigen::Vector3d dirs[] = {{0.2, 1, 0.4}, {1, -0.2, 0.1}, {-0.5, 0.3, 1}, {0.6, -1, -0.3}};
    Eigen::Matrix<double, 6, 1> xi;
    xi << dirs[variant].normalized() * fraction * keyframe_->mean_depth,
        axes[variant].normalized() * degrees * 3.14159265358979 / 180.0;
    return T * SE3d::Exp(xi);
  }
};

TEST_F(Se3TrackerRenderTest, ConvergesFromLargeInitialErrorNoiseFree) {
  const TrackingReference reference(keyframe_->frame, keyframe_->idepth, keyframe_->variance);
  ASSERT_GT(reference.Level(0).Size(), 20000u);
  const auto frame = test::RenderTestFrame(*scene_, Pose(10), 1);
  Se3Tracker tracker;
  for (int variant = 0; variant < 4; ++variant) {
    const SE3d guess = Perturb(TrueKfFrame(10), 3.0, 0.05, variant);
    const TrackingResult result = tracker.TrackFrom(reference, *frame, guess, {});
    const auto error = ComparePoses(result.T_kf_frame, TrueKfFrame(10));
    EXPECT_EQ(result.status, TrackingStatus::kOk) << result.stats.reason;
    EXPECT_LT(error.rotation_deg, 0.05) << "variant " << variant;
    EXPECT_LT(error.translation, 0.001 * keyframe_->mean_depth) << "variant " << variant;
    // Views at other distances sample other mip levels (slightly less contrast), so the
    // fitted gain is not exactly 1 even without an exposure change.
    EXPECT_NEAR(result.affine.a, 0.0, 0.03);
  }
}

TEST_F(Se3TrackerRenderTest, AffineModelHandlesExposureChangeWithNoise) {
  const TrackingReference reference(keyframe_->frame, keyframe_->idepth, keyframe_->variance);
  const auto frame = test::RenderTestFrame(*scene_, Pose(10), 1, 1.6f, 2.0, 7);
  Se3Tracker with_affine;
  Se3TrackerOptions no_affine_options;
  no_affine_options.estimate_affine = false;
  Se3Tracker without_affine(no_affine_options);
  for (int variant = 0; variant < 2; ++variant) {
    const SE3d guess = Perturb(TrueKfFrame(10), 3.0, 0.05, variant);
    const TrackingResult good = with_affine.TrackFrom(reference, *frame, guess, {});
    const auto error = ComparePoses(good.T_kf_frame, TrueKfFrame(10));
    EXPECT_EQ(good.status, TrackingStatus::kOk) << good.stats.reason;
    EXPECT_LT(error.rotation_deg, 0.2);
    EXPECT_LT(error.translation, 0.005 * keyframe_->mean_depth);
    // x1.6 saturates the brightest pixels at 255, which pulls the fitted gain down a little.
    EXPECT_NEAR(good.affine.Gain(), 1.6, 0.1);
    // Without the brightness model the same problem fails: large error or not ok.
    const TrackingResult bad = without_affine.TrackFrom(reference, *frame, guess, {});
    const auto bad_error = ComparePoses(bad.T_kf_frame, TrueKfFrame(10));
    const bool failed = bad.status != TrackingStatus::kOk || bad_error.rotation_deg > 0.2 ||
                        bad_error.translation > 0.005 * keyframe_->mean_depth;
    EXPECT_TRUE(failed) << "rot " << bad_error.rotation_deg << " trans " << bad_error.translation
                        << " status " << ToString(bad.status);
  }
}

TEST_F(Se3TrackerRenderTest, ReportsLostOnOtherSceneAndBlackFrame) {
  const TrackingReference reference(keyframe_->frame, keyframe_->idepth, keyframe_->variance);
  Se3Tracker tracker;
  const synth::Scene corridor = synth::MakeScene("corridor", 3);
  const auto other = test::RenderTestFrame(corridor, SE3d(), 2);
  const TrackingResult other_result = tracker.Track(reference, *other, {SE3d()});
  EXPECT_EQ(other_result.status, TrackingStatus::kLost)
      << "good ratio " << other_result.stats.good_ratio;
  const auto black =
      std::make_shared<const Frame>(3, 0.0, test::TestCamera(), ImageU8(640, 480, 0));
  const TrackingResult black_result = tracker.Track(reference, *black, {SE3d()});
  EXPECT_EQ(black_result.status, TrackingStatus::kLost);
  EXPECT_FALSE(black_result.stats.reason.empty());
}

TEST_F(Se3TrackerRenderTest, HypothesesRecoverFromABadFirstGuess) {
  const TrackingReference reference(keyframe_->frame, keyframe_->idepth, keyframe_->variance);
  const auto frame = test::RenderTestFrame(*scene_, Pose(10), 1);
  Se3Tracker tracker;
  // First guess far off (12 degrees); the second hypothesis is the truth plus a small error.
  const std::vector<SE3d> hypotheses = {Perturb(TrueKfFrame(10), 12.0, 0.3, 0),
                                        Perturb(TrueKfFrame(10), 1.0, 0.01, 1)};
  const TrackingResult result = tracker.Track(reference, *frame, hypotheses);
  EXPECT_EQ(result.status, TrackingStatus::kOk);
  EXPECT_GT(result.stats.hypotheses_tried, 1);
  EXPECT_LT(ComparePoses(result.T_kf_frame, TrueKfFrame(10)).rotation_deg, 0.05);
}

// An "ok" result with few consistent points is searched again; the search keeps a right
// result right, and is skipped above the bar or with the bar at 0.
TEST_F(Se3TrackerRenderTest, SuspectOkResultsAreSearchedAgain) {
  const TrackingReference reference(keyframe_->frame, keyframe_->idepth, keyframe_->variance);
  const auto frame = test::RenderTestFrame(*scene_, Pose(10), 1);
  const std::vector<SE3d> start = {Perturb(TrueKfFrame(10), 1.0, 0.01, 0)};
  Se3Tracker tracker;
  const TrackingResult first = tracker.Track(reference, *frame, start);
  ASSERT_EQ(first.status, TrackingStatus::kOk);
  EXPECT_GT(first.stats.good_ratio, tracker.Options().suspect_good_ratio);
  EXPECT_EQ(first.stats.hypotheses_tried, 1);
  // A bar above what the result has: searched, and the result stays right.
  Se3TrackerOptions demanding;
  demanding.suspect_good_ratio = 1.0f;
  Se3Tracker strict(demanding);
  const TrackingResult searched = strict.Track(reference, *frame, start);
  // The start, 6 rotations of it, 6 of the result, and the result's rotation with the start's
  // translation.
  EXPECT_EQ(searched.stats.hypotheses_tried, 14);
  EXPECT_EQ(searched.status, TrackingStatus::kOk);
  EXPECT_LT(ComparePoses(searched.T_kf_frame, TrueKfFrame(10)).rotation_deg, 0.05);
  // The bar at 0: never searched.
  Se3TrackerOptions off;
  off.suspect_good_ratio = 0.0f;
  Se3Tracker trusting(off);
  EXPECT_EQ(trusting.Track(reference, *frame, start).stats.hypotheses_tried, 1);
}

// The first run's rotation carries information even when the run is lost: from 9 degrees
// of pitch off (translation right) the room's first run ends lost, 6.5 degrees off; its
// rotation with the start's translation converges.
TEST_F(Se3TrackerRenderTest, TheFirstRunsRotationIsTriedWithTheStartsTranslation) {
  const TrackingReference reference(keyframe_->frame, keyframe_->idepth, keyframe_->variance);
  const auto frame = test::RenderTestFrame(*scene_, Pose(14), 1);
  Eigen::Matrix<double, 6, 1> pitch = Eigen::Matrix<double, 6, 1>::Zero();
  pitch[3] = 9.0 * 3.14159265358979 / 180.0;
  const SE3d start = TrueKfFrame(14) * SE3d::Exp(pitch);
  Se3Tracker tracker;
  const TrackingResult first = tracker.TrackFrom(reference, *frame, start, {});
  EXPECT_EQ(first.status, TrackingStatus::kLost);
  EXPECT_GT(ComparePoses(first.T_kf_frame, TrueKfFrame(14)).rotation_deg, 3.0);
  const TrackingResult found = tracker.Track(reference, *frame, {start});
  EXPECT_EQ(found.status, TrackingStatus::kOk) << found.stats.reason;
  EXPECT_LT(ComparePoses(found.T_kf_frame, TrueKfFrame(14)).rotation_deg, 0.05);
}

// A camera that starts turning between two frames: the only hypothesis (constant velocity)
// is 11 degrees of yaw from the truth. Rotations of 1.7 degrees alone (the default) do not
// reach its basin; the wide search angles do.
TEST_F(Se3TrackerRenderTest, WideSearchRotationsRecoverASuddenTurn) {
  const TrackingReference reference(keyframe_->frame, keyframe_->idepth, keyframe_->variance);
  const auto frame = test::RenderTestFrame(*scene_, Pose(10), 1);
  Eigen::Matrix<double, 6, 1> yaw = Eigen::Matrix<double, 6, 1>::Zero();
  yaw[4] = 11.0 * 3.14159265358979 / 180.0;
  const std::vector<SE3d> start = {TrueKfFrame(10) * SE3d::Exp(yaw)};
  Se3Tracker narrow;
  const TrackingResult missed = narrow.Track(reference, *frame, start);
  const double missed_deg = ComparePoses(missed.T_kf_frame, TrueKfFrame(10)).rotation_deg;
  EXPECT_TRUE(missed.status != TrackingStatus::kOk || missed_deg > 1.0)
      << ToString(missed.status) << " " << missed_deg;
  Se3TrackerOptions wide_options;
  wide_options.search_rotations_deg = {1.7, 5.7, 11.5};
  Se3Tracker wide(wide_options);
  const TrackingResult found = wide.Track(reference, *frame, start);
  EXPECT_EQ(found.status, TrackingStatus::kOk) << found.stats.reason;
  EXPECT_LT(ComparePoses(found.T_kf_frame, TrueKfFrame(10)).rotation_deg, 0.05);
  Se3TrackerOptions bad;
  bad.search_rotations_deg = {0.0};
  EXPECT_THROW(bad.Check(), std::invalid_argument);
  bad.search_rotations_deg = {};
  EXPECT_THROW(bad.Check(), std::invalid_argument);
}

TEST_F(Se3TrackerRenderTest, DeterministicResults) {
  const TrackingReference reference(keyframe_->frame, keyframe_->idepth, keyframe_->variance);
  const auto frame = test::RenderTestFrame(*scene_, Pose(6), 1, 1.2f, 3.0);
  Se3Tracker a, b;
  const TrackingResult ra = a.TrackFrom(reference, *frame, SE3d(), {});
  const TrackingResult rb = b.TrackFrom(reference, *frame, SE3d(), {});
  EXPECT_EQ(ra.T_kf_frame.Matrix(), rb.T_kf_frame.Matrix());
  EXPECT_EQ(ra.affine.a, rb.affine.a);
}

// The point budget keeps at most max_points_per_level per level, spread over the image like
// the full set, and a tracker on the thinned reference still converges.
TEST_F(Se3TrackerRenderTest, PointBudgetThinsEveryLevelEvenly) {
  const TrackingReference full(keyframe_->frame, keyframe_->idepth, keyframe_->variance);
  TrackingReferenceOptions options;
  options.max_points_per_level = 3000;
  const TrackingReference thin(keyframe_->frame, keyframe_->idepth, keyframe_->variance, options);
  ASSERT_EQ(thin.NumLevels(), full.NumLevels());
  for (int l = 0; l < full.NumLevels(); ++l) {
    const ReferenceLevel& a = full.Level(l);
    const ReferenceLevel& b = thin.Level(l);
    EXPECT_EQ(b.Size(), std::min<std::size_t>(a.Size(), 3000u)) << "level " << l;
    const auto mean = [](const std::vector<float>& v) {
      return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
    };
    const double width = keyframe_->frame->Level(l).Width();
    EXPECT_NEAR(mean(b.u), mean(a.u), 0.02 * width) << "level " << l;
    EXPECT_NEAR(mean(b.v), mean(a.v), 0.02 * width) << "level " << l;
    EXPECT_NEAR(mean(b.idepth), mean(a.idepth), 0.02 * mean(a.idepth)) << "level " << l;
  }
  EXPECT_EQ(thin.MeanIdepth(), full.MeanIdepth());
  const auto frame = test::RenderTestFrame(*scene_, Pose(10), 1);
  Se3Tracker tracker;
  const TrackingResult result =
      tracker.TrackFrom(thin, *frame, Perturb(TrueKfFrame(10), 3.0, 0.05, 0), {});
  EXPECT_EQ(result.status, TrackingStatus::kOk);
  EXPECT_LT(ComparePoses(result.T_kf_frame, TrueKfFrame(10)).rotation_deg, 0.1);
}

// A reference built from level 1 on has exactly the coarse levels of a full one (they are
// summed from level 0's pixels in the same order) and an empty level 0; a tracker that would
// read level 0 refuses it, one that stops at level 1 tracks the same pose bit for bit.
TEST_F(Se3TrackerRenderTest, ReferenceFromLevelOneHasTheSameCoarseLevels) {
  const TrackingReference full(keyframe_->frame, keyframe_->idepth, keyframe_->variance);
  TrackingReferenceOptions options;
  options.finest_level = 1;
  const TrackingReference coarse(keyframe_->frame, keyframe_->idepth, keyframe_->variance, options);
  ASSERT_EQ(coarse.NumLevels(), full.NumLevels());
  EXPECT_EQ(coarse.FinestLevel(), 1);
  EXPECT_EQ(coarse.Level(0).Size(), 0u);
  ASSERT_GT(full.Level(0).Size(), 0u);
  for (int l = 1; l < full.NumLevels(); ++l) {
    for (const auto field : kReferenceLevelFields) {
      EXPECT_EQ(coarse.Level(l).*field, full.Level(l).*field) << "level " << l;
    }
  }
  EXPECT_EQ(coarse.MeanIdepth(), full.MeanIdepth());
  const auto frame = test::RenderTestFrame(*scene_, Pose(10), 1);
  const SE3d guess = Perturb(TrueKfFrame(10), 3.0, 0.05, 0);
  Se3Tracker tracker;  // finest level 1
  EXPECT_EQ(tracker.TrackFrom(coarse, *frame, guess, {}).T_kf_frame.Matrix(),
            tracker.TrackFrom(full, *frame, guess, {}).T_kf_frame.Matrix());
  Se3TrackerOptions level0;
  level0.finest_level = 0;
  Se3Tracker fine(level0);
  EXPECT_THROW(fine.TrackFrom(coarse, *frame, guess, {}), std::invalid_argument);
}

TEST(TrackingReference, CoarseLevelsAreInverseVarianceWeighted) {
  ImageU8 image(64, 48);
  for (int y = 0; y < 48; ++y) {
    for (int x = 0; x < 64; ++x) image(x, y) = static_cast<std::uint8_t>((x % 8) * 30);
  }
  const auto frame = std::make_shared<const Frame>(
      0, 0.0, PinholeCamera(64, 48, 50, 50, 31.5, 23.5), image, PyramidOptions{2, 8});
  ImageF idepth(64, 48, 0.0f), variance(64, 48, 0.0f);
  idepth(20, 20) = 1.0f;
  variance(20, 20) = 1.0f;
  idepth(21, 20) = 2.0f;
  variance(21, 20) = 3.0f;  // weight 1/3
  TrackingReferenceOptions options;
  options.min_gradient = 0.0f;
  const TrackingReference reference(frame, idepth, variance, options);
  ASSERT_EQ(reference.Level(0).Size(), 2u);
  ASSERT_EQ(reference.Level(1).Size(), 1u);
  EXPECT_FLOAT_EQ(reference.Level(1).idepth[0], (1.0f + 2.0f / 3.0f) / (1.0f + 1.0f / 3.0f));
  EXPECT_FLOAT_EQ(reference.Level(1).variance[0], 1.0f / (1.0f + 1.0f / 3.0f));
  EXPECT_EQ(reference.Level(1).u[0], 10.0f);
  EXPECT_THROW(TrackingReference(frame, ImageF(10, 10), variance), std::invalid_argument);
}

}  // namespace
}  // namespace parallax
