#pragma once
// A gtest fixture: the room scene (seed 3) shaken for 40 frames, with frame 0 rendered as a
// keyframe with ground-truth depth (shared by the suite's tests, rendered once).

#include <gtest/gtest.h>

#include <memory>

#include "tests/tracking/render_fixture.hpp"

namespace parallax::test {

class RoomShakeKeyframeTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scene_ = std::make_unique<synth::Scene>(synth::MakeScene("room", 3));
    options_.scene = "room";
    options_.motion = "shake";
    options_.frames = 40;
    keyframe_ = std::make_unique<RenderedKeyframe>(RenderTestKeyframe(*scene_, Pose(0)));
  }
  static void TearDownTestSuite() {
    keyframe_.reset();
    scene_.reset();
  }
  /// The camera's pose at frame i (T_w_c).
  static SE3d Pose(int i) { return synth::FramePose(options_, *scene_, i); }
  /// Frame i's true pose in the keyframe (frame 0).
  static SE3d TrueKfFrame(int i) { return keyframe_->T_w_c.Inverse() * Pose(i); }

  static inline std::unique_ptr<synth::Scene> scene_;
  static inline synth::SynthOptions options_;
  static inline std::unique_ptr<RenderedKeyframe> keyframe_;
};

}  // namespace parallax::test
