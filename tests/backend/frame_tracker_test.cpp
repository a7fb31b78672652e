// FrameTracker's constant-velocity guess over a gap of frames: at a camera's rate the
// real-time mode drops the frames that arrive while it is busy (0.5 s after the start on
// real texture), and a skipped frame leaves a gap too. The guess must follow the time the gap
// took, and without that the same gap must fail, so the scene really tests it.

#include "backend/frame_tracker.hpp"

#include <gtest/gtest.h>

#include <memory>

#include "tests/tracking/render_fixture.hpp"
#include "tracking/tracking_reference.hpp"

namespace parallax {
namespace {

class FrameTrackerGapTest : public ::testing::Test {
 protected:
  FrameTrackerGapTest() : scene_(synth::MakeScene("room", 1)) {
    motion_.motion = "orbit";
    motion_.frames = 300;  // the real-texture orbit's speed: about 1.2 degrees a frame
    keyframe_ = test::RenderTestKeyframe(scene_, Pose(0));
    reference_ =
        std::make_unique<TrackingReference>(keyframe_.frame, keyframe_.idepth, keyframe_.variance);
  }

  SE3d Pose(int index) const { return synth::FramePose(motion_, scene_, index); }

  /// Frame `index` at its input time (30 frames/s).
  std::shared_ptr<const Frame> FrameAt(int index) const {
    return std::make_shared<const Frame>(index, index / motion_.fps, test::TestCamera(),
                                         test::RenderTestImage(scene_, Pose(index)));
  }

  /// Tracks frames 1 and 2 (the velocity), then frame 2 + gap; the last result.
  TrackingResult TrackAfterGap(int gap, double velocity_rescale_ratio) const {
    Se3TrackerOptions options;
    options.velocity_rescale_ratio = velocity_rescale_ratio;
    FrameTracker tracker(options);
    for (const int index : {1, 2}) {
      EXPECT_EQ(tracker.Track(*reference_, *FrameAt(index)).status, TrackingStatus::kOk);
    }
    return tracker.Track(*reference_, *FrameAt(2 + gap));
  }

  synth::SynthOptions motion_;
  synth::Scene scene_;
  test::RenderedKeyframe keyframe_;
  std::unique_ptr<TrackingReference> reference_;
};

TEST_F(FrameTrackerGapTest, TheVelocityFollowsTheTimeOfAGap) {
  const int gap = 12;  // 11 frames dropped: 0.4 s, about 14 degrees and 0.4 m of the orbit
  const SE3d T_kf_true = Pose(0).Inverse() * Pose(2 + gap);
  const TrackingResult rescaled = TrackAfterGap(gap, 1.5);
  ASSERT_EQ(rescaled.status, TrackingStatus::kOk);
  const test::PoseError error = test::ComparePoses(rescaled.T_kf_frame, T_kf_true);
  EXPECT_LT(error.rotation_deg, 0.2);
  EXPECT_LT(error.translation, 0.01);  // metres (the keyframe's depth is the true one)
  // Measured: 0.007 degrees and 0.5 mm off. With the velocity as measured over one frame
  // (the ratio never reached) the same frame is lost (the best start is 13 degrees off).
  const TrackingResult as_measured = TrackAfterGap(gap, 1e9);
  const test::PoseError off = test::ComparePoses(as_measured.T_kf_frame, T_kf_true);
  EXPECT_TRUE(as_measured.status == TrackingStatus::kLost || off.rotation_deg > 2.0)
      << ToString(as_measured.status) << ", " << off.rotation_deg << " degrees off";
}

TEST_F(FrameTrackerGapTest, FrameRateJitterKeepsTheVelocityAsMeasured) {
  // A gap within the ratio (here no gap at all) tracks the next frame the same either way.
  const TrackingResult with = TrackAfterGap(1, 1.5);
  const TrackingResult without = TrackAfterGap(1, 1e9);
  ASSERT_EQ(with.status, TrackingStatus::kOk);
  EXPECT_EQ(with.T_kf_frame.Log(), without.T_kf_frame.Log());
}

// A result that is not confident with a residual above max_residual_jump times the last
// tracked frame's disagrees with the frames before it; right after a lost frame a confident
// one is held to the same bar (on the room patrols such results were 20-90 degrees off).
TEST_F(FrameTrackerGapTest, AResidualFarAboveTheLastFramesDisagreesWithHistory) {
  FrameTracker tracker{Se3TrackerOptions{}};
  for (const int index : {1, 2}) {
    ASSERT_EQ(tracker.Track(*reference_, *FrameAt(index)).status, TrackingStatus::kOk);
  }
  const double last = tracker.State().residual_rms;
  ASSERT_GT(last, 0.0);
  TrackingResult result;
  result.status = TrackingStatus::kOk;
  result.stats.good_ratio = 0.65;  // ok, not confident
  result.stats.residual_rms = 2.9 * last;
  EXPECT_TRUE(tracker.AgreesWithHistory(result));
  result.stats.residual_rms = 3.1 * last;
  EXPECT_FALSE(tracker.AgreesWithHistory(result));
  result.stats.good_ratio = 0.9;  // confident, with the motion model behind it
  EXPECT_TRUE(tracker.AgreesWithHistory(result));
  // A black frame is lost; the state stays the last tracked frame's.
  const Frame black(3, 3.0 / motion_.fps, test::TestCamera(), ImageU8(640, 480));
  ASSERT_EQ(tracker.Track(*reference_, black).status, TrackingStatus::kLost);
  EXPECT_EQ(tracker.State().residual_rms, last);
  EXPECT_FALSE(tracker.AgreesWithHistory(result));  // confident, but right after a loss
  Se3TrackerOptions off;
  off.max_residual_jump = 0.0;
  EXPECT_TRUE(FrameTracker(off).AgreesWithHistory(result));
}

// Right after a loss only a confident result re-acquires: ok, at least suspect_good_ratio
// consistent and at least min_reacquisition_points consistent points (on the room patrols,
// recoveries of 61-66% consistent points, and later of 79-87% but only 172-401 points, after
// a textureless wall were 25-104 degrees off).
TEST(FrameTracker, OnlyAConfidentResultReacquires) {
  const FrameTracker tracker{Se3TrackerOptions{}};
  TrackingResult result;
  result.status = TrackingStatus::kOk;
  result.stats.good_ratio = 0.9;
  result.stats.points_good = Se3TrackerOptions{}.min_reacquisition_points;
  EXPECT_TRUE(tracker.Reacquires(result));
  result.stats.points_good -= 1;  // confident, but too few points to pin a pose down
  EXPECT_FALSE(tracker.Reacquires(result));
  Se3TrackerOptions counting_nothing;
  counting_nothing.min_reacquisition_points = 0;
  EXPECT_TRUE(FrameTracker(counting_nothing).Reacquires(result));
  result.stats.points_good = 5000;
  result.stats.good_ratio = 0.65;  // ok, but a result the tracker would search again
  EXPECT_FALSE(tracker.Reacquires(result));
  result.stats.good_ratio = 0.9;
  result.status = TrackingStatus::kPoor;
  EXPECT_FALSE(tracker.Reacquires(result));
  Se3TrackerOptions trusting;
  trusting.suspect_good_ratio = 0.0f;
  result.status = TrackingStatus::kOk;
  result.stats.good_ratio = 0.65;
  EXPECT_TRUE(FrameTracker(trusting).Reacquires(result));
}

}  // namespace
}  // namespace parallax
