// Epipolar stereo observations on a rendered room with ground-truth depth: short searched
// segments must not bias the inverse depth, and a search window the frame border cuts is
// reported out of image rather than answered with the best wrong match left inside.

#include "depth/epipolar_search.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/validity_mask.hpp"
#include "tests/tracking/render_fixture.hpp"

namespace parallax {
namespace {

class EpipolarSearchTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scene_ = std::make_unique<synth::Scene>(synth::MakeScene("room", 3));
    synth::SynthOptions options;
    options.frames = 40;
    T_w_kf_ = synth::FramePose(options, *scene_, 0);
    keyframe_ =
        std::make_unique<test::RenderedKeyframe>(test::RenderTestKeyframe(*scene_, T_w_kf_));
  }
  static void TearDownTestSuite() {
    keyframe_.reset();
    scene_.reset();
  }

  // A frame displaced by t (keyframe coordinates, metres), no rotation.
  static std::shared_ptr<const Frame> FrameAt(const Eigen::Vector3d& t) {
    return test::RenderTestFrame(*scene_, T_w_kf_ * SE3d(SO3d(), t), 1);
  }

  struct Summary {
    int ok = 0;
    int out_of_image = 0;
    double median_ratio = 0.0;  ///< observed / true inverse depth
  };

  // Observes every pixel with a true depth from a prior centred on the truth with relative
  // sigma `prior_sigma`, with the search capped at `max_length` pixels.
  static Summary ObserveAll(const Frame& frame, const Eigen::Vector3d& t, float prior_sigma,
                            float max_length = 30.0f) {
    const DepthFilterOptions options;
    const StereoFrame stereo{&frame, SE3d(SO3d(), t).Inverse()};
    const EpipolarSearch search(*keyframe_->frame, stereo, options);
    std::vector<double> ratios;
    Summary s;
    const ImageF& truth = keyframe_->idepth;
    for (int y = 4; y < truth.Height() - 4; y += 2) {
      for (int x = 4; x < truth.Width() - 4; x += 2) {
        const float d = truth(x, y);
        if (!(d > 0.0f)) continue;
        const StereoObservation obs = search.Observe(
            x, y, d * (1.0f - 2.0f * prior_sigma), d * (1.0f + 2.0f * prior_sigma), d, max_length);
        if (obs.status == StereoStatus::kOutOfImage) ++s.out_of_image;
        if (obs.status != StereoStatus::kOk) continue;
        ++s.ok;
        ratios.push_back(obs.idepth / d);
      }
    }
    if (!ratios.empty()) {
      const auto middle = ratios.begin() + static_cast<std::ptrdiff_t>(ratios.size() / 2);
      std::nth_element(ratios.begin(), middle, ratios.end());
      s.median_ratio = *middle;
    }
    return s;
  }

  /// Observes every 7th pixel with a true depth by both searches (prior +-10% around the
  /// truth): the statuses must agree; `compare(x, y, d, a, b)` gets every pair observed ok.
  template <typename Compare>
  static void ForEachPair(const EpipolarSearch& a, const EpipolarSearch& b, Compare compare) {
    const ImageF& truth = keyframe_->idepth;
    for (int y = 20; y < truth.Height() - 20; y += 7) {
      for (int x = 20; x < truth.Width() - 20; x += 7) {
        const float d = truth(x, y);
        if (!(d > 0.0f)) continue;
        const StereoObservation oa = a.Observe(x, y, 0.9f * d, 1.1f * d, d, 30.0f);
        const StereoObservation ob = b.Observe(x, y, 0.9f * d, 1.1f * d, d, 30.0f);
        ASSERT_EQ(oa.status, ob.status);
        if (oa.status == StereoStatus::kOk) compare(x, y, d, oa, ob);
      }
    }
  }

  static inline std::unique_ptr<synth::Scene> scene_;
  static inline SE3d T_w_kf_;
  static inline std::unique_ptr<test::RenderedKeyframe> keyframe_;
};

// Forward motion of 2 cm at 2-4 m depth: disparities of a few pixels, and a 5% prior spans
// well under two pixels of the line. Before the segment was padded and centred, the first
// sample sat on the far end of such a segment and the median observation was ~3% too far.
TEST_F(EpipolarSearchTest, ShortSegmentsAreUnbiased) {
  const Eigen::Vector3d t(0.0, 0.0, 0.02);
  const auto frame = FrameAt(t);
  for (const float sigma : {0.02f, 0.05f, 0.1f}) {
    const Summary s = ObserveAll(*frame, t, sigma);
    SCOPED_TRACE(testing::Message() << "prior sigma " << sigma);
    EXPECT_GT(s.ok, 5000);
    EXPECT_NEAR(s.median_ratio, 1.0, 0.005);
  }
}

TEST_F(EpipolarSearchTest, LateralMotionIsUnbiased) {
  const Eigen::Vector3d t(0.03, 0.01, 0.0);
  const auto frame = FrameAt(t);
  const Summary s = ObserveAll(*frame, t, 0.05f);
  EXPECT_GT(s.ok, 5000);
  EXPECT_NEAR(s.median_ratio, 1.0, 0.005);
}

// Sideways by 30 cm: points near the left border of the keyframe leave the frame. A full-range
// search (a new pixel) for such a point has a window the border cuts; it must be reported out
// of image, not answered with the best wrong match left inside (which is always too far).
// Points whose match stays well inside still match, at the right depth.
TEST_F(EpipolarSearchTest, WindowCutByTheBorderIsOutOfImage) {
  const Eigen::Vector3d t(0.3, 0.0, 0.0);
  const auto frame = FrameAt(t);
  const DepthFilterOptions options;
  const EpipolarSearch search(*keyframe_->frame, {frame.get(), SE3d(SO3d(), t).Inverse()}, options);
  const float mid = std::sqrt(options.min_idepth * options.max_idepth);
  const double fx = keyframe_->frame->Camera(0).Fx();
  int left_tried = 0, left_ok = 0, inside_tried = 0, inside_ok = 0, inside_right = 0;
  const ImageF& truth = keyframe_->idepth;
  for (int y = 8; y < truth.Height() - 8; y += 3) {
    for (int x = 8; x < truth.Width() - 8; x += 3) {
      const float d = truth(x, y);
      if (!(d > 0.0f)) continue;
      const double true_match_x = x - fx * t.x() * d;
      const bool leaves = true_match_x < 0.0;
      const bool stays = true_match_x > 80.0 && x < truth.Width() - 80;
      if (!leaves && !stays) continue;
      const StereoObservation obs = search.Observe(x, y, options.min_idepth, options.max_idepth,
                                                   mid, options.max_search_length_new);
      if (leaves) {
        ++left_tried;
        left_ok += obs.status == StereoStatus::kOk;
      } else {
        ++inside_tried;
        if (obs.status != StereoStatus::kOk) continue;
        ++inside_ok;
        inside_right += std::abs(obs.idepth / d - 1.0f) < 0.1f;
      }
    }
  }
  EXPECT_GT(left_tried, 500);
  EXPECT_EQ(left_ok, 0);
  EXPECT_GT(inside_ok, inside_tried / 10);
  EXPECT_GT(inside_right, 0.9 * inside_ok);
}

// Where the frame sees no input (a `full` rectification's border, here its left 200 columns)
// the search stops as at the image border: no match is made there, and none elsewhere is lost.
TEST_F(EpipolarSearchTest, NoMatchWhereTheFrameSeesNoInput) {
  const Eigen::Vector3d t(0.05, 0.0, 0.0);
  ImageU8 seen(640, 480, 1);
  for (int y = 0; y < 480; ++y) std::fill_n(seen.Row(y), 200, std::uint8_t{0});
  const PinholeCamera masked =
      test::TestCamera().WithValidity(std::make_shared<const ValidityMask>(seen));
  const Frame frame(1, 0.0, masked, test::RenderTestImage(*scene_, T_w_kf_ * SE3d(SO3d(), t)));
  const DepthFilterOptions options;
  const EpipolarSearch search(*keyframe_->frame, {&frame, SE3d(SO3d(), t).Inverse()}, options);
  const double fx = keyframe_->frame->Camera(0).Fx();
  int border_ok = 0, border_tried = 0, inside_ok = 0;
  const ImageF& truth = keyframe_->idepth;
  for (int y = 8; y < truth.Height() - 8; y += 3) {
    for (int x = 8; x < truth.Width() - 8; x += 3) {
      const float d = truth(x, y);
      if (!(d > 0.0f)) continue;
      const StereoObservation obs = search.Observe(x, y, 0.8f * d, 1.2f * d, d, 30.0f);
      const double match_x = x - fx * t.x() * d;
      if (match_x < 195.0) {
        ++border_tried;
        border_ok += obs.status == StereoStatus::kOk;
      } else if (match_x > 230.0) {
        inside_ok += obs.status == StereoStatus::kOk;
      }
    }
  }
  EXPECT_GT(border_tried, 1000);
  EXPECT_EQ(border_ok, 0);
  EXPECT_GT(inside_ok, 1000);
}

// The baseline's uncertainty enters as d^2 (baseline_sigma / |t|)^2: the same match, with a
// variance that grows as the baseline shrinks.
TEST_F(EpipolarSearchTest, BaselineUncertaintyAddsToTheVariance) {
  const Eigen::Vector3d t(0.01, 0.0, 0.0);
  const auto frame = FrameAt(t);
  DepthFilterOptions without;
  without.baseline_sigma = 0.0f;
  DepthFilterOptions with;
  with.baseline_sigma = 0.002f;
  const StereoFrame stereo{frame.get(), SE3d(SO3d(), t).Inverse()};
  const EpipolarSearch a(*keyframe_->frame, stereo, without), b(*keyframe_->frame, stereo, with);
  int compared = 0;
  ForEachPair(a, b, [&](int, int, float, const StereoObservation& oa, const StereoObservation& ob) {
    ++compared;
    EXPECT_EQ(oa.idepth, ob.idepth);
    const float extra = oa.idepth * oa.idepth * 0.2f * 0.2f;  // (0.002 / 0.01)^2
    EXPECT_NEAR(ob.variance - oa.variance, extra, 1e-3f * extra);
  });
  EXPECT_GT(compared, 500);
}

// An uncertain rotation enters as alpha^2 (rotation_sigma * f . l)^2, f being the rotation's
// image motion at the pixel (where a point at infinity goes) and l the epipolar direction: the
// same match, with a variance that grows with the rotation (zero for a pure translation).
// alpha and f are computed here from the geometry.
TEST_F(EpipolarSearchTest, RotationUncertaintyAddsToTheVariance) {
  const SE3d T_kf_frame(SO3d::Exp(Eigen::Vector3d(0.01, 0.04, 0.0)),
                        Eigen::Vector3d(0.02, 0.0, 0.05));
  const auto frame = test::RenderTestFrame(*scene_, T_w_kf_ * T_kf_frame, 1);
  DepthFilterOptions without;
  without.rotation_sigma = 0.0f;
  DepthFilterOptions with;
  with.rotation_sigma = 0.02f;
  const StereoFrame stereo{frame.get(), T_kf_frame.Inverse()};
  const EpipolarSearch a(*keyframe_->frame, stereo, without), b(*keyframe_->frame, stereo, with);
  const PinholeCamera& camera = keyframe_->frame->Camera(0);
  const Eigen::Matrix3d R = stereo.T_frame_kf.RotationMatrix();
  const Eigen::Vector3d t = stereo.T_frame_kf.Translation();
  int compared = 0;
  int within_2_percent = 0;
  double largest_extra = 0.0;  // relative to the variance without
  ForEachPair(
      a, b, [&](int x, int y, float d, const StereoObservation& oa, const StereoObservation& ob) {
        ++compared;
        EXPECT_EQ(oa.idepth, ob.idepth);
        const Eigen::Vector2d u(x, y);
        const Eigen::Vector3d Rq = R * camera.Unproject(u);
        const auto project = [&](double idepth) { return camera.Project(Rq + idepth * t); };
        const Eigen::Vector2d dir = (project(1.1 * d) - project(0.9 * d)).normalized();
        const double h = 1e-4 * oa.idepth;
        const double alpha = 2.0 * h / (project(oa.idepth + h) - project(oa.idepth - h)).norm();
        const double along = 0.02 * (project(0.0) - u).dot(dir);
        const double extra = alpha * alpha * along * along;
        // alpha here is a derivative, the search's a difference over a pixel: equal to 2% but
        // near the epipole, where the inverse depth along the line curves.
        EXPECT_NEAR(ob.variance - oa.variance, extra, 0.1 * extra + 1e-12);
        if (std::abs(ob.variance - oa.variance - extra) <= 0.02 * extra + 1e-12) ++within_2_percent;
        largest_extra = std::max(largest_extra, extra / oa.variance);
      });
  EXPECT_GT(compared, 500);
  EXPECT_GE(within_2_percent, compared * 99 / 100);
  EXPECT_GT(largest_extra, 0.1);  // the term matters: about 20 px of image motion

  // A pure translation moves nothing at infinity: the variance is unchanged.
  const Eigen::Vector3d shift(0.02, 0.0, 0.05);
  const auto translated = FrameAt(shift);
  const StereoFrame straight{translated.get(), SE3d(SO3d(), shift).Inverse()};
  const EpipolarSearch c(*keyframe_->frame, straight, without),
      e(*keyframe_->frame, straight, with);
  int unchanged = 0;
  ForEachPair(c, e, [&](int, int, float, const StereoObservation& oc, const StereoObservation& oe) {
    EXPECT_EQ(oc.variance, oe.variance);
    ++unchanged;
  });
  EXPECT_GT(unchanged, 500);
}

// MarkSearchableRow answers, for a whole row at once, Observe's first test: 0 exactly where
// Observe returns kSkipped before it searches. Checked on every pixel for a sideways, a
// forward (epipole inside the image) and a turning motion, with a gate strict enough that
// both answers occur, and the pattern's rescale gate opened wide, so that Observe's only
// other kSkipped cannot occur.
TEST_F(EpipolarSearchTest, SearchableRowIsObservesOwnSkipTest) {
  const std::vector<SE3d> motions = {
      SE3d(SO3d(), Eigen::Vector3d(0.03, 0.01, 0.0)),
      SE3d(SO3d(), Eigen::Vector3d(0.002, -0.001, 0.05)),
      SE3d(SO3d::Exp(Eigen::Vector3d(0.02, -0.03, 0.01)), Eigen::Vector3d(-0.02, 0.01, 0.02))};
  DepthFilterOptions options;
  options.min_gradient_along_line_share = 0.3f;
  options.min_rescale = 1e-3f;
  options.max_rescale = 1e3f;
  for (const SE3d& T_kf_frame : motions) {
    const auto frame = test::RenderTestFrame(*scene_, T_w_kf_ * T_kf_frame, 1);
    const StereoFrame stereo{frame.get(), T_kf_frame.Inverse()};
    const EpipolarSearch search(*keyframe_->frame, stereo, options);
    const int w = keyframe_->frame->Level(0).Width(), h = keyframe_->frame->Level(0).Height();
    std::vector<std::uint8_t> searchable(static_cast<std::size_t>(w));
    int skipped = 0, searched = 0, disagree = 0;
    for (int y = 3; y < h - 3; ++y) {
      search.MarkSearchableRow(y, searchable.data());
      for (int x = 3; x < w - 3; ++x) {
        const bool observe_skips =
            search.Observe(x, y, 0.2f, 0.6f, 0.35f, 30.0f).status == StereoStatus::kSkipped;
        const bool marked = searchable[static_cast<std::size_t>(x)] != 0;
        disagree += static_cast<int>(marked == observe_skips);
        skipped += static_cast<int>(!marked);
        searched += static_cast<int>(marked);
      }
    }
    EXPECT_EQ(disagree, 0);
    EXPECT_GT(skipped, 1000);
    EXPECT_GT(searched, 1000);
  }
}

}  // namespace
}  // namespace parallax
