// The start on an orbit: a pair whose turn and sideways step are not separated gives the
// first keyframe a common inverse-depth offset, which the trajectory then carries as a
// turn-rate error (docs/math/two_view.md, "The turn/sideways-step ambiguity").

#include <gtest/gtest.h>

#include <string>

#include "backend/system.hpp"
#include "core/angles.hpp"
#include "tests/backend/orbit_fixture.hpp"
#include "tools/synth/scene.hpp"
#include "tools/synth/synthetic_sequence.hpp"

namespace parallax {
namespace {

/// Heading error (degrees) of frame `last` relative to frame 0, against ground truth,
/// after running the first `last + 1` frames of the 300-frame room orbit of seed 3.
double HeadingErrorAfter(int last, double max_offset_sigma) {
  const synth::SynthOptions synth_options = test::RoomOrbit(300, 3);
  const synth::Scene scene = synth::MakeScene(synth_options.scene, synth_options.seed);
  SystemOptions options;
  options.bootstrap.max_offset_sigma = max_offset_sigma;
  System system(synth::SynthCamera(synth_options), options);
  for (int i = 0; i <= last; ++i) {
    system.ProcessFrame(synth::RenderSynthFrame(synth_options, scene, i).image,
                        synth::FrameTimestamp(synth_options, i));
  }
  const std::vector<FramePose> poses = system.Trajectory();
  if (poses.size() != static_cast<std::size_t>(last) + 1) return 180.0;
  const SO3d estimated = (poses.front().T_w_c.Inverse() * poses.back().T_w_c).Rotation();
  const SO3d truth = (synth::FramePose(synth_options, scene, 0).Inverse() *
                      synth::FramePose(synth_options, scene, last))
                         .Rotation();
  return (estimated.Inverse() * truth).Log().norm() * kRadToDeg;
}

// Measured at frame 60 (about 70 degrees turned): 4.5 degrees with the start's pair after 4
// frames (the gate off), 0.43 with the gate's pair after 5 frames.
TEST(StartConditioning, AnOrbitsStartWaitsForAPairThatSeparatesTurnAndStep) {
  constexpr int kLast = 60;
  const double gated = HeadingErrorAfter(kLast, SystemOptions{}.bootstrap.max_offset_sigma);
  const double ungated = HeadingErrorAfter(kLast, 0.0);
  RecordProperty("heading_error_deg", std::to_string(gated));
  RecordProperty("heading_error_without_gate_deg", std::to_string(ungated));
  EXPECT_LT(gated, 1.0);
  EXPECT_GT(ungated, 2.0);  // the scenario still shows what the gate is for
}

}  // namespace
}  // namespace parallax
