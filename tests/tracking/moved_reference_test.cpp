// TrackingReference::MovedTo: a keyframe's tracking points seen from another frame (the
// real-time mode's bridge, docs/realtime.md).

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "tests/tracking/render_fixture.hpp"
#include "tests/tracking/room_shake_fixture.hpp"
#include "tracking/se3_tracker.hpp"
#include "tracking/tracking_reference.hpp"

namespace parallax {
namespace {

using test::ComparePoses;
using test::RenderedKeyframe;

class MovedReferenceTest : public test::RoomShakeKeyframeTest {};

TEST_F(MovedReferenceTest, MovedToItsOwnFrameEveryPointStays) {
  TrackingReferenceOptions options;
  options.finest_level = 1;
  const TrackingReference reference(keyframe_->frame, keyframe_->idepth, keyframe_->variance,
                                    options);
  const TrackingReference moved = reference.MovedTo(keyframe_->frame, SE3d(), 1.0f, 0.0f);
  ASSERT_EQ(moved.NumLevels(), reference.NumLevels());
  EXPECT_EQ(moved.FinestLevel(), 1);
  EXPECT_EQ(moved.Level(0).Size(), 0u);
  for (int l = 1; l < reference.NumLevels(); ++l) {
    const ReferenceLevel& a = reference.Level(l);
    const ReferenceLevel& b = moved.Level(l);
    ASSERT_EQ(b.Size(), a.Size()) << "level " << l;
    ASSERT_GT(a.Size(), 0u);
    for (std::size_t i = 0; i < a.Size(); ++i) {
      ASSERT_EQ(b.u[i], a.u[i]);
      ASSERT_EQ(b.v[i], a.v[i]);
      ASSERT_EQ(b.ray_x[i], a.ray_x[i]);
      ASSERT_EQ(b.ray_y[i], a.ray_y[i]);
      ASSERT_EQ(b.intensity[i], a.intensity[i]);
      ASSERT_FLOAT_EQ(b.idepth[i], a.idepth[i]);
      ASSERT_NEAR(b.variance[i], a.variance[i], 1e-6f * a.variance[i]);
    }
  }
}

// Moved into the view of frame 10 with its true pose, the points carry that view's own
// depth, and a later frame tracked on them gets its true pose relative to frame 10.
TEST_F(MovedReferenceTest, MovedPointsCarryTheOtherViewsDepthAndTrackFromIt) {
  TrackingReferenceOptions options;
  options.finest_level = 1;
  const TrackingReference reference(keyframe_->frame, keyframe_->idepth, keyframe_->variance,
                                    options);
  const RenderedKeyframe view = test::RenderTestKeyframe(*scene_, Pose(10));
  const SE3d T_view_kf = Pose(10).Inverse() * keyframe_->T_w_c;
  const TrackingReference moved = reference.MovedTo(view.frame, T_view_kf, 1.0f, 0.0f);
  const ReferenceLevel& level = moved.Level(1);
  ASSERT_GT(level.Size(), reference.Level(1).Size() / 2);
  std::vector<double> relative_errors;
  for (std::size_t i = 0; i < level.Size(); ++i) {
    // The view's true inverse depth at the level-1 pixel's four level-0 pixels.
    const int x = 2 * static_cast<int>(level.u[i]), y = 2 * static_cast<int>(level.v[i]);
    const float truth = view.idepth(x, y);
    if (truth <= 0.0f) continue;  // near a depth edge: no truth there
    relative_errors.push_back(std::abs(level.idepth[i] - truth) / truth);
  }
  ASSERT_GT(relative_errors.size(), level.Size() / 2);
  std::nth_element(
      relative_errors.begin(),
      relative_errors.begin() + static_cast<std::ptrdiff_t>(relative_errors.size() / 2),
      relative_errors.end());
  EXPECT_LT(relative_errors[relative_errors.size() / 2], 0.01);

  const auto later = test::RenderTestFrame(*scene_, Pose(14), 2);
  const SE3d truth = Pose(10).Inverse() * Pose(14);
  Se3Tracker tracker;
  const TrackingResult result = tracker.TrackFrom(moved, *later, SE3d(), {});
  EXPECT_EQ(result.status, TrackingStatus::kOk) << result.stats.reason;
  const auto error = ComparePoses(result.T_kf_frame, truth);
  EXPECT_LT(error.rotation_deg, 0.05);
  EXPECT_LT(error.translation, 0.002 * keyframe_->mean_depth);
}

// A view of another place: most intensities do not match (the test is propagation's, which
// tolerates 20 grey levels plus gradient, so a third lands by chance); the same place keeps
// nearly every point.
TEST_F(MovedReferenceTest, PointsLandOnlyWhereTheViewLooksLikeThem) {
  const TrackingReference reference(keyframe_->frame, keyframe_->idepth, keyframe_->variance);
  const synth::Scene other = synth::MakeScene("desk", 5);
  const auto elsewhere = test::RenderTestFrame(other, Pose(0), 1);
  const TrackingReference moved = reference.MovedTo(elsewhere, SE3d(), 1.0f, 0.0f);
  EXPECT_LT(moved.Level(0).Size(), reference.Level(0).Size() / 2);
  const auto same = test::RenderTestFrame(*scene_, Pose(0), 1);
  EXPECT_GT(reference.MovedTo(same, SE3d(), 1.0f, 0.0f).Level(0).Size(),
            reference.Level(0).Size() * 9 / 10);
}

// Two points that land on one pixel: the nearer one (larger inverse depth) is seen.
TEST(MovedReference, OfTwoPointsOnOnePixelTheNearerStays) {
  ImageU8 image(64, 48);
  for (int y = 0; y < 48; ++y) {
    for (int x = 0; x < 64; ++x) image(x, y) = static_cast<std::uint8_t>(10 + 2 * x);
  }
  const auto frame = std::make_shared<const Frame>(
      0, 0.0, PinholeCamera(64, 48, 50, 50, 31.5, 23.5), image, PyramidOptions{2, 8});
  ImageF idepth(64, 48, 0.0f), variance(64, 48, 0.0f);
  idepth(20, 20) = 1.0f;
  variance(20, 20) = 0.01f;
  idepth(21, 20) = 2.0f;
  variance(21, 20) = 0.01f;
  TrackingReferenceOptions options;
  options.min_gradient = 0.0f;
  const TrackingReference reference(frame, idepth, variance, options);
  ASSERT_EQ(reference.Level(0).Size(), 2u);
  // 2 cm to the side: the far point moves by fx * t * idepth = 1 pixel, the near one by 2;
  // both land on x = 19.
  const SE3d T_to_kf(SO3d(), Eigen::Vector3d(-0.02, 0.0, 0.0));
  const TrackingReference moved = reference.MovedTo(frame, T_to_kf, 1.0f, 0.0f);
  ASSERT_EQ(moved.Level(0).Size(), 1u);
  EXPECT_EQ(moved.Level(0).u[0], 19.0f);
  EXPECT_FLOAT_EQ(moved.Level(0).idepth[0], 2.0f);
  EXPECT_EQ(moved.Level(0).intensity[0], 48.0f);  // the view's intensity at (19, 20)
  EXPECT_THROW(reference.MovedTo(nullptr, SE3d(), 1.0f, 0.0f), std::invalid_argument);
}

}  // namespace
}  // namespace parallax
