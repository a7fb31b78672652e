// World poses of frames from their keyframe anchors: the graph's correction of a keyframe is
// spread over the frames tracked towards it, so that a camera moving steadily, whose tracking
// against the first keyframe drifts steadily, comes out steady once the graph has corrected
// the second keyframe.

#include "backend/frame_trajectory.hpp"

#include <gtest/gtest.h>

#include <map>

#include "backend/system.hpp"
#include "core/angles.hpp"
#include "tests/backend/orbit_fixture.hpp"
#include "tests/backend/scenario_options.hpp"
#include "tools/eval/evaluation.hpp"
#include "tools/synth/scene.hpp"
#include "tools/synth/synthetic_sequence.hpp"

namespace parallax {
namespace {

// Frames 0..10 of a camera moving 2 cm a frame along x while turning 0.5 degrees a frame
// about y. Keyframe A is frame 0, keyframe B frame 5 (grown from A), frames 6..10 are tracked
// against B.
SE3d TruePose(int frame) {
  return SE3d(SO3d::Exp(Eigen::Vector3d(0.0, 0.5 / kRadToDeg * frame, 0.0)),
              Eigen::Vector3d(0.02 * frame, 0.0, 0.0));
}

// Tracking against A drifts steadily: frame f (0..5) is off by Exp(f / 5 * drift).
Sim3d::Tangent Drift() {
  Sim3d::Tangent drift;
  drift << 0.004, -0.002, 0.001, 0.01, -0.02, 0.005, 0.03;
  return drift;
}

struct Chain {
  std::vector<std::optional<AnchoredPose>> anchors;
  std::map<std::int64_t, TrackedKeyframe> tracked;
  std::map<std::int64_t, Sim3d> keyframe_poses;  // after optimisation: B where it truly is

  FrameAnchors View() const {
    FrameAnchors view;
    view.anchors = &anchors;
    view.tracked = &tracked;
    view.keyframe_pose = [this](std::int64_t id) -> std::optional<Sim3d> {
      const auto found = keyframe_poses.find(id);
      if (found == keyframe_poses.end()) return std::nullopt;
      return found->second;
    };
    return view;
  }
};

Chain DriftingChain() {
  Chain chain;
  for (int f = 0; f <= 5; ++f) {
    const Sim3d tracked = Sim3d::Exp(f / 5.0 * Drift()) * Sim3d(TruePose(f));
    if (f < 5) chain.anchors.push_back(AnchoredPose{0, tracked.RigidPart()});
    if (f == 5) chain.tracked[5] = TrackedKeyframe{0, tracked};
  }
  for (int f = 5; f <= 10; ++f) {
    chain.anchors.push_back(AnchoredPose{5, TruePose(5).Inverse() * TruePose(f)});
  }
  chain.keyframe_poses[0] = Sim3d();
  chain.keyframe_poses[5] = Sim3d(TruePose(5));
  return chain;
}

double PositionError(const std::vector<FramePose>& poses, int frame) {
  return (poses.at(static_cast<std::size_t>(frame)).T_w_c.Translation() -
          TruePose(frame).Translation())
      .norm();
}

TEST(FrameWorldPoses, WithoutSpreadingFramesKeepTheirPoseRelativeToTheirKeyframe) {
  const Chain chain = DriftingChain();
  const std::vector<FramePose> poses = FrameWorldPoses(chain.View(), false);
  ASSERT_EQ(poses.size(), 11u);
  for (int f = 0; f < 5; ++f) {
    const SE3d expected = chain.anchors[static_cast<std::size_t>(f)]->T_kf_frame;
    EXPECT_LT(
        (poses[static_cast<std::size_t>(f)].T_w_c.Translation() - expected.Translation()).norm(),
        1e-12);
  }
  // The step from frame 4 (tracked against A, 4/5 of the drift) to B (corrected) is a jump.
  EXPECT_GT(PositionError(poses, 4), 0.003);
  EXPECT_LT(PositionError(poses, 5), 1e-12);
}

TEST(FrameWorldPoses, SpreadingTheCorrectionUndoesASteadyDrift) {
  const Chain chain = DriftingChain();
  const std::vector<FramePose> poses = FrameWorldPoses(chain.View(), true);
  ASSERT_EQ(poses.size(), 11u);
  for (int f = 0; f <= 10; ++f) {
    EXPECT_EQ(poses[static_cast<std::size_t>(f)].frame_id, f);
    EXPECT_LT(PositionError(poses, f), 1e-9) << "frame " << f;
    const SO3d rotation_error =
        poses[static_cast<std::size_t>(f)].T_w_c.Rotation().Inverse() * TruePose(f).Rotation();
    EXPECT_LT(rotation_error.Log().norm(), 1e-9) << "frame " << f;
  }
}

TEST(FrameWorldPoses, NoSpreadAcrossALossOrTowardsAKeyframeThatGrewElsewhere) {
  // A frame without a pose between A's frames and B: nothing ties the run to B.
  Chain lost = DriftingChain();
  lost.anchors[4].reset();
  const std::vector<FramePose> after_loss = FrameWorldPoses(lost.View(), true);
  ASSERT_EQ(after_loss.size(), 10u);
  EXPECT_GT(PositionError(after_loss, 3), 0.003);  // as tracked

  // B grew from another keyframe (a return to an older one): A's frames stay as tracked.
  Chain elsewhere = DriftingChain();
  elsewhere.tracked[5].parent = 99;
  const std::vector<FramePose> unrelated = FrameWorldPoses(elsewhere.View(), true);
  EXPECT_GT(PositionError(unrelated, 4), 0.003);
}

TEST(FrameWorldPoses, FramesOfAKeyframeNoLongerInTheMapHaveNoPose) {
  Chain chain = DriftingChain();
  chain.keyframe_poses.erase(0);  // a restart withdrew A
  const std::vector<FramePose> poses = FrameWorldPoses(chain.View(), true);
  ASSERT_EQ(poses.size(), 6u);
  EXPECT_EQ(poses.front().frame_id, 5);
}

// Frames 0..4 tracked right against A, B's own tracking 3 cm off sideways (a step to it that
// breaks the run's motion), the graph puts B right: that correction is B's alone.
TEST(FrameWorldPoses, AKeyframeWhoseOwnTrackingSlippedDoesNotMoveTheFramesBeforeIt) {
  Chain chain = DriftingChain();
  for (int f = 0; f < 5; ++f) {
    chain.anchors[static_cast<std::size_t>(f)] = AnchoredPose{0, TruePose(f)};
  }
  chain.tracked[5].S_parent_kf =
      Sim3d(SE3d(SO3d(), Eigen::Vector3d(0.0, 0.03, 0.0))) * Sim3d(TruePose(5));
  for (const bool guarded : {true, false}) {
    FrameAnchors view = chain.View();
    view.max_step_change = guarded ? 1.0 : 1e9;
    const std::vector<FramePose> poses = FrameWorldPoses(view, true);
    ASSERT_EQ(poses.size(), 11u);
    if (guarded) {
      for (int f = 0; f <= 10; ++f) EXPECT_LT(PositionError(poses, f), 1e-12) << "frame " << f;
    } else {
      EXPECT_GT(PositionError(poses, 4), 0.02);  // moved by 4/5 of B's slip
    }
  }
}

// The 300-frame room orbit of seed 1: the camera returns near its start, a neighbour edge
// there corrects the heading and the graph spreads that over the chain. Kept rigidly on their
// keyframes the frames show each keyframe's share as a step (the largest per-frame error
// 43-45 mm where the median is under 1 mm); spread, they do not. (Seed 2, used until
// 2026-12-06, has such a correction or none depending on the tracker's float rounding: 70
// mm, then 2.8 mm after the four-lane sums; seed 1 has it under both.)
double LargestPerFrameError(bool spread) {
  const synth::SynthOptions synth_options = test::RoomOrbit(300, 1);
  const synth::Scene scene = synth::MakeScene(synth_options.scene, synth_options.seed);
  // The keyframe rule this was measured with (with today's, the graph moves this orbit's
  // keyframes by millimetres: no steps to remove, so nothing to test).
  SystemOptions options = test::WithRelativeKeyframeRule();
  options.spread_keyframe_corrections = spread;
  System system(synth::SynthCamera(synth_options), options);
  Trajectory truth;
  for (int i = 0; i < synth_options.frames; ++i) {
    const double t = synth::FrameTimestamp(synth_options, i);
    system.ProcessFrame(synth::RenderSynthFrame(synth_options, scene, i).image, t);
    truth.push_back({t, synth::FramePose(synth_options, scene, i)});
  }
  system.FinishMapping();
  Trajectory estimate;
  for (const FramePose& pose : system.Trajectory())
    estimate.push_back({pose.timestamp, pose.T_w_c});
  EXPECT_EQ(estimate.size(), truth.size());
  const EvaluationReport report = Evaluate(estimate, truth, {});
  return report.rpe_per_frame.translation.max;
}

TEST(FrameWorldPosesInThePipeline, AnOrbitsTrajectoryHasNoStepsAtItsKeyframes) {
  const double spread = LargestPerFrameError(true);
  const double rigid = LargestPerFrameError(false);
  RecordProperty("largest_per_frame_error_spread_mm", std::to_string(1000.0 * spread));
  RecordProperty("largest_per_frame_error_rigid_mm", std::to_string(1000.0 * rigid));
  EXPECT_LT(spread, 0.01);  // measured 6.9-7.0 mm
  EXPECT_GT(rigid, 0.03);   // measured 43-45 mm: the steps this removes
}

}  // namespace
}  // namespace parallax
