// A run never loses work: stale files go, a corrupt frame is skipped and reported (or ends the
// run with its outputs marked failed), an interrupted run leaves a consistent partial result.

#include "tools/run_outputs.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "temp_dir.hpp"
#include "tools/dataset/input_error.hpp"
#include "tools/dataset/trajectory.hpp"
#include "tools/run_pipeline.hpp"
#include "tools/synth/synthetic_sequence.hpp"

namespace parallax {
namespace {

namespace fs = std::filesystem;

class RunOutputsTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<test::TempDirAt>("parallax_run_outputs_test");
    synth::SynthOptions options;
    options.frames = 40;
    options.width = 320;
    options.height = 240;
    synth::WriteSyntheticSequence(options, dir_->File("room"));
  }
  static void TearDownTestSuite() { dir_.reset(); }
  static inline std::unique_ptr<test::TempDirAt> dir_;

  static nlohmann::json Json(const std::string& file) {
    std::ifstream in(file);
    return nlohmann::json::parse(in);
  }
  /// A copy of the room with frame `index`'s image overwritten by garbage bytes.
  static std::string CorruptCopy(const std::string& name, int index) {
    std::string copy = dir_->File(name);
    fs::remove_all(copy);
    fs::copy(dir_->File("room"), copy, fs::copy_options::recursive);
    std::ifstream list(copy + "/rgb.txt");
    std::string line;
    int k = 0;
    while (std::getline(list, line)) {
      if (line.empty() || line[0] == '#') continue;
      if (k++ == index) std::ofstream(copy + "/" + line.substr(line.find(' ') + 1)) << "not a png";
    }
    return copy;
  }
};

TEST_F(RunOutputsTest, StaleFilesOfAnEarlierRunAreRemoved) {
  const std::string out = dir_->File("stale");
  fs::create_directories(out);
  std::ofstream(out + "/trajectory.times.txt") << "from an earlier KITTI-format run\n";
  std::ofstream(out + "/notes.txt") << "not ours\n";
  RunOptions run;
  run.dataset = dir_->File("room");
  run.out_dir = out;
  RunDataset(run);
  EXPECT_FALSE(fs::exists(out + "/trajectory.times.txt"));
  EXPECT_TRUE(fs::exists(out + "/notes.txt"));  // only the run's own names are removed
  const auto manifest = Json(out + "/run.json");
  EXPECT_EQ(manifest["status"], "complete");
  EXPECT_TRUE(manifest["complete"].get<bool>());
  for (const auto& f : manifest["files"]) EXPECT_TRUE(fs::exists(out + "/" + f.get<std::string>()));
  EXPECT_FALSE(fs::exists(out + "/trajectory.txt.partial"));
}

// map.ply is binary: a header any PLY reader takes, then one 15-byte record a point
// (x, y, z as little-endian floats, the grey level as red = green = blue).
TEST_F(RunOutputsTest, TheMapIsABinaryPlyWithTheGreyLevelOfEachPoint) {
  const std::string out = dir_->File("ply");
  RunOptions run;
  run.dataset = dir_->File("room");
  run.out_dir = out;
  const RunSummary summary = RunDataset(run);
  ASSERT_GT(summary.map_points, 1000u);
  std::ifstream in(out + "/map.ply", std::ios::binary);
  std::string line, header;
  while (std::getline(in, line) && line != "end_header") header += line + "\n";
  EXPECT_EQ(header, "ply\nformat binary_little_endian 1.0\nelement vertex " +
                        std::to_string(summary.map_points) +
                        "\nproperty float x\nproperty float y\nproperty float z\n"
                        "property uchar red\nproperty uchar green\nproperty uchar blue\n");
  std::vector<char> records((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_EQ(records.size(), summary.map_points * 15);
  std::set<int> greys;
  for (std::size_t k = 0; k < summary.map_points; ++k) {
    float xyz[3];
    std::memcpy(xyz, records.data() + 15 * k, sizeof(xyz));
    for (const float v : xyz) ASSERT_TRUE(std::isfinite(v));
    const auto* rgb = reinterpret_cast<const std::uint8_t*>(records.data() + 15 * k + 12);
    ASSERT_TRUE(rgb[0] == rgb[1] && rgb[1] == rgb[2]);
    greys.insert(rgb[0]);
  }
  EXPECT_GT(greys.size(), 50u);  // the room's texture, not a constant
}

TEST_F(RunOutputsTest, ACorruptFrameIsSkippedAndReported) {
  RunOptions run;
  run.dataset = CorruptCopy("corrupt", 35);
  run.out_dir = dir_->File("corrupt_out");
  const RunSummary s = RunDataset(run);
  EXPECT_EQ(s.frames, 40);
  EXPECT_EQ(s.frames_unreadable, 1);
  EXPECT_GE(s.frames_tracked, 38);
  EXPECT_EQ(Json(run.out_dir + "/stats.json")["frames_unreadable"], 1);
  std::ifstream log(run.out_dir + "/frames.csv");
  std::stringstream text;
  text << log.rdbuf();
  EXPECT_NE(text.str().find("35,"), std::string::npos);
  EXPECT_NE(text.str().find("unreadable"), std::string::npos);
}

TEST_F(RunOutputsTest, FatalUnreadableEndsTheRunWithItsOutputsMarkedFailed) {
  RunOptions run;
  run.dataset = CorruptCopy("fatal", 30);
  run.out_dir = dir_->File("fatal_out");
  run.fatal_unreadable = true;
  EXPECT_THROW(RunDataset(run), InputError);
  const auto manifest = Json(run.out_dir + "/run.json");
  EXPECT_NE(manifest["status"].get<std::string>().find("failed"), std::string::npos);
  // The 30 frames before it are there, from the map as it stood.
  const Trajectory partial = ReadTumTrajectory(run.out_dir + "/trajectory.txt");
  EXPECT_GE(partial.size(), 28u);
  EXPECT_LE(partial.size(), 30u);
}

TEST_F(RunOutputsTest, AStopRequestLeavesAConsistentPartialResult) {
  // The flag is polled between frames: set before the run, it stops after none; here a
  // frame budget plays the signal's part deterministically, then the flag.
  std::atomic<bool> stop{true};
  RunOptions run;
  run.dataset = dir_->File("room");
  run.out_dir = dir_->File("stopped");
  run.stop = &stop;
  EXPECT_THROW(RunDataset(run), InputError);  // no frame at all: "has no frames"
  stop = false;
  run.max_frames = 25;
  const RunSummary s = RunDataset(run);
  EXPECT_EQ(s.frames, 25);
  const Trajectory online = ReadTumTrajectory(run.out_dir + "/trajectory_online.txt");
  const Trajectory final_poses = ReadTumTrajectory(run.out_dir + "/trajectory.txt");
  EXPECT_EQ(online.size(), final_poses.size());
  EXPECT_EQ(final_poses.size(), static_cast<std::size_t>(s.frames_tracked));
}

TEST_F(RunOutputsTest, AnUnusableOutputFolderFailsBeforeTheFirstFrame) {
  // A file where the folder should be (permissions do not stop root, who runs CI).
  std::ofstream(dir_->File("blocker")) << "a file\n";
  RunOptions run;
  run.dataset = dir_->File("room");
  run.out_dir = dir_->File("blocker/out");
  try {
    RunDataset(run);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("blocker/out"), std::string::npos) << e.what();
  }
}

TEST_F(RunOutputsTest, EventsAboutAnEarlierFrameNameItsIndex) {
  // The real-time mode reports what mapping did behind the caller with a later frame: the
  // frame log says which frame an event is about when it is not the row's.
  const std::string out = dir_->File("events_out");
  FrameResult later;
  later.events.push_back({SystemEvent::Kind::kKeyframeCreated, 1, 1});
  later.events.push_back({SystemEvent::Kind::kLost, 2, -1});
  {
    RunOutputs outputs(out, RunOptions::TrajectoryFormat::kTum, dir_->File("room"));
    FrameResult first;
    first.events.push_back({SystemEvent::Kind::kLost, 0, -1});
    outputs.LogFrame(10, 1.0, 0, first);  // dataset index 10 is the engine's frame 0
    outputs.LogFrame(11, 1.1, 1, FrameResult{});
    outputs.LogFrame(12, 1.2, 2, later);
  }
  std::ifstream log(out + "/frames.csv");
  std::vector<std::string> events;
  for (std::string line; std::getline(log, line);)
    events.push_back(line.substr(line.rfind(',') + 1));
  ASSERT_EQ(events.size(), 4u);
  EXPECT_EQ(events[1], "lost");
  EXPECT_EQ(events[2], "");
  EXPECT_EQ(events[3], "keyframe@11;lost");
  EXPECT_EQ(EventNames(later.events), "keyframe;lost");  // no frame names without a lookup
}

}  // namespace
}  // namespace parallax
