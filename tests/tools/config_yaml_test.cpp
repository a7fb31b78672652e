// The pipeline configuration file: overrides, defaults, and errors with file:line.

#include "tools/config_yaml.hpp"

#include <gtest/gtest.h>

#include "tests/tools/temp_dir.hpp"
#include "tools/dataset/input_error.hpp"

namespace parallax {
namespace {

TEST(ConfigYaml, OverridesOnlyTheGivenKeys) {
  test::TempDir dir;
  SystemOptions options;
  ApplyConfigYaml(dir.Write("c.yaml",
                            "tracker:\n  finest_level: 0\n  max_iterations: [2, 4, 6]\n"
                            "depth:\n  seed: 7\nsystem:\n  keyframe_distance: 0.3\n"),
                  &options);
  EXPECT_EQ(options.tracker.finest_level, 0);
  EXPECT_EQ(options.tracker.max_iterations, (std::vector<int>{2, 4, 6}));
  EXPECT_EQ(options.depth.seed, 7u);
  EXPECT_DOUBLE_EQ(options.keyframe_distance, 0.3);
  EXPECT_EQ(options.pyramid.max_levels, SystemOptions{}.pyramid.max_levels);  // untouched
  ApplyConfigYaml(dir.Write("empty.yaml", ""), &options);  // empty file keeps everything
  EXPECT_EQ(options.depth.seed, 7u);
}

TEST(ConfigYaml, TextGetsTheSameKeysAndErrorsWithItsName) {
  SystemOptions options;
  ApplyConfigYamlText("realtime:\n  max_pending_frames: 3\n  keyframe_wait_factor: 2.0\n",
                      "options_yaml", &options);
  EXPECT_EQ(options.realtime.max_pending_frames, 3);
  EXPECT_DOUBLE_EQ(options.realtime.keyframe_wait_factor, 2.0);
  EXPECT_FALSE(options.realtime.enabled);  // the mode is the caller's flag, not an option
  try {
    ApplyConfigYamlText("realtime:\n  mapping_threads: 0\n", "options_yaml", &options);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("options_yaml"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("mapping_threads"), std::string::npos) << e.what();
  }
  EXPECT_EQ(options.realtime.mapping_threads, 1);  // a refused text changes nothing
}

TEST(ConfigYaml, ErrorsNameFileLineAndKey) {
  test::TempDir dir;
  SystemOptions options;
  try {
    ApplyConfigYaml(dir.Write("unknown.yaml", "tracker:\n  finest_level: 1\n  finest_levle: 2\n"),
                    &options);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.Line(), 3);
    EXPECT_NE(std::string(e.what()).find("tracker.finest_levle"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ApplyConfigYaml(dir.Write("type.yaml", "depth:\n  seed: abc\n"), &options),
               InputError);
  EXPECT_THROW(ApplyConfigYaml(dir.Write("section.yaml", "loop:\n  enabled: true\n"), &options),
               InputError);
  try {
    ApplyConfigYaml(dir.Write("check.yaml", "system:\n  keyframe_distance: -1\n"), &options);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("keyframe_distance"), std::string::npos) << e.what();
  }
  EXPECT_DOUBLE_EQ(options.keyframe_distance,
                   SystemOptions{}.keyframe_distance);  // unchanged on error
}

}  // namespace
}  // namespace parallax
