// The keyframe rule's distance in the pipeline: the image distance (ParallaxMoments) makes
// fewer keyframes when the camera moves along its view, and as many when it moves sideways.

#include <gtest/gtest.h>

#include <string>

#include "tests/tools/temp_dir.hpp"
#include "tools/dataset/trajectory.hpp"
#include "tools/eval/evaluation.hpp"
#include "tools/run_pipeline.hpp"
#include "tools/synth/synthetic_sequence.hpp"

namespace parallax {
namespace {

struct KeyframeCount {
  int keyframes = 0;
  double ate_percent_of_path = 0.0;
};

KeyframeCount RunWith(const test::TempDirAt& dir, const std::string& sequence, bool in_image) {
  RunOptions run;
  run.dataset = dir.File(sequence);
  run.out_dir = dir.File(sequence + (in_image ? "_image" : "_relative"));
  run.system.keyframe_distance_in_image = in_image;
  const RunSummary summary = RunDataset(run);
  EXPECT_EQ(summary.frames_tracked, summary.frames) << run.out_dir;
  return {summary.keyframes, Evaluate(ReadTumTrajectory(run.out_dir + "/trajectory.txt"),
                                      ReadTumTrajectory(run.dataset + "/groundtruth.txt"), {})
                                 .ate_rmse_percent_of_path};
}

TEST(KeyframeRule, TheImageDistanceSpacesKeyframesAlongTheViewAndNotAcrossIt) {
  const test::TempDirAt dir("parallax_keyframe_rule");
  synth::SynthOptions walk;  // a street walked forward at 10 frames/s
  walk.scene = "street";
  walk.motion = "walk";
  walk.frames = 60;
  walk.fps = 10.0;
  synth::WriteSyntheticSequence(walk, dir.File("walk"));
  synth::SynthOptions orbit;  // a room orbited, looking inwards: the camera moves sideways
  orbit.motion = "orbit";
  orbit.frames = 60;
  synth::WriteSyntheticSequence(orbit, dir.File("orbit"));

  const KeyframeCount walk_relative = RunWith(dir, "walk", false);
  const KeyframeCount walk_image = RunWith(dir, "walk", true);
  ::testing::Test::RecordProperty(
      "walk_keyframes",
      std::to_string(walk_relative.keyframes) + " -> " + std::to_string(walk_image.keyframes));
  EXPECT_LT(walk_image.keyframes, 0.8 * walk_relative.keyframes)
      << walk_image.keyframes << " against " << walk_relative.keyframes;
  EXPECT_LT(walk_image.ate_percent_of_path, 1.0);

  const KeyframeCount orbit_relative = RunWith(dir, "orbit", false);
  const KeyframeCount orbit_image = RunWith(dir, "orbit", true);
  ::testing::Test::RecordProperty(
      "orbit_keyframes",
      std::to_string(orbit_relative.keyframes) + " -> " + std::to_string(orbit_image.keyframes));
  EXPECT_NEAR(orbit_image.keyframes, orbit_relative.keyframes, 2);
  EXPECT_LT(orbit_image.ate_percent_of_path, 1.0);
}

}  // namespace
}  // namespace parallax
