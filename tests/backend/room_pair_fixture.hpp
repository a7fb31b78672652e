#pragma once
// A reference view of the rendered room and frames moved from it, for the two-view tests.

#include <gtest/gtest.h>

#include "tests/tracking/render_fixture.hpp"

namespace parallax::test {

class RoomPairTest : public ::testing::Test {
 protected:
  RoomPairTest()
      : scene_(synth::MakeScene("room", 1)),
        camera_(synth::SynthCamera({})),
        T_w_ref_(synth::FramePose({}, scene_, 0)) {}

  ImageU8 RenderImage(const SE3d& T_w_c, float gain, double noise_sigma) const {
    return RenderTestImage(scene_, T_w_c, gain, noise_sigma, 7);
  }

  /// Frame pose after moving by `T_ref_frame` (camera motion in the reference frame).
  SE3d Moved(const SE3d& T_ref_frame) const { return T_w_ref_ * T_ref_frame; }

  synth::Scene scene_;
  PinholeCamera camera_;
  SE3d T_w_ref_;
};

}  // namespace parallax::test
