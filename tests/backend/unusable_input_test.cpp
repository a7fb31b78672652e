// Hostile input end to end: random noise, black, white, blown-out and tiny sequences get no
// pose and say so (stats.json outcome), instead of a confident garbage trajectory.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <random>

#include "backend/system.hpp"
#include "tests/tools/temp_dir.hpp"
#include "tools/dataset/image_file.hpp"
#include "tools/run_pipeline.hpp"
#include "tools/synth/synthetic_sequence.hpp"

namespace parallax {
namespace {

/// A TUM-layout folder of `n` frames made by `pixel(frame, x, y)`, with a pinhole calibration.
template <typename Pixel>
std::string WriteSequence(const test::TempDir& dir, const std::string& name, int w, int h, int n,
                          Pixel pixel) {
  std::string list;
  for (int i = 0; i < n; ++i) {
    cv::Mat m(h, w, CV_8UC1);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) m.at<std::uint8_t>(y, x) = pixel(i, x, y);
    }
    const std::string file = name + "/rgb/" + std::to_string(i) + ".png";
    std::filesystem::create_directories(std::filesystem::path(dir.File(file)).parent_path());
    WritePngFile(dir.File(file), m);
    list += std::to_string(i / 30.0) + " rgb/" + std::to_string(i) + ".png\n";
  }
  dir.Write(name + "/rgb.txt", list);
  const double f = 0.8 * w;
  dir.Write(name + "/calibration.yaml",
            "model: pinhole\nwidth: " + std::to_string(w) + "\nheight: " + std::to_string(h) +
                "\nfx: " + std::to_string(f) + "\nfy: " + std::to_string(f) +
                "\ncx: " + std::to_string(w / 2.0) + "\ncy: " + std::to_string(h / 2.0) + "\n");
  return dir.File(name);
}

RunSummary RunOn(const std::string& dataset) {
  RunOptions run;
  run.dataset = dataset;
  run.out_dir = dataset + "_out";
  return RunDataset(run);
}

TEST(UnusableInput, NoiseBlackWhiteAndBlownOutSequencesGetNoPose) {
  const test::TempDir dir;
  std::mt19937_64 rng(1);
  std::uniform_int_distribution<int> u(0, 255);
  const auto noise = [&](int, int, int) { return static_cast<std::uint8_t>(u(rng)); };
  const auto black = [](int, int, int) { return std::uint8_t{0}; };
  const auto white = [](int, int, int) { return std::uint8_t{255}; };
  const auto blown = [](int, int x, int y) {
    return static_cast<std::uint8_t>((x / 40 + y / 40) % 5 == 0 ? 200 : 255);
  };
  for (const auto& [name, summary] :
       {std::pair{"noise", RunOn(WriteSequence(dir, "noise", 320, 240, 60, noise))},
        std::pair{"black", RunOn(WriteSequence(dir, "black", 320, 240, 20, black))},
        std::pair{"white", RunOn(WriteSequence(dir, "white", 320, 240, 20, white))},
        std::pair{"blown", RunOn(WriteSequence(dir, "blown", 320, 240, 20, blown))},
        std::pair{"tiny", RunOn(WriteSequence(dir, "tiny", 1, 1, 10, black))}}) {
    EXPECT_EQ(summary.frames_tracked, 0) << name;
    EXPECT_EQ(summary.keyframes, 0) << name;
    EXPECT_EQ(summary.frames_unusable, summary.frames) << name;
    EXPECT_EQ(summary.Outcome(), "tracked_nothing") << name;
    EXPECT_EQ(summary.map_points, 0u) << name;
  }
}

TEST(UnusableInput, ADarkStretchInsideARenderIsLostThenTracked) {
  // A rendered room with frames 20-29 black (a covered lens): those are lost, the others are
  // posed, and no invented pose fills the gap.
  const test::TempDir dir;
  synth::SynthOptions options;
  options.frames = 60;
  synth::WriteSyntheticSequence(options, dir.File("room"));
  // Rewrite the listed images of frames 20-29 as black frames.
  std::ifstream list(dir.File("room/rgb.txt"));
  std::string line;
  int index = 0;
  while (std::getline(list, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (index >= 20 && index < 30) {
      const std::string file = line.substr(line.find(' ') + 1);
      WritePngFile(dir.File("room/" + file), cv::Mat(480, 640, CV_8UC1, cv::Scalar(0)));
    }
    ++index;
  }
  const RunSummary s = RunOn(dir.File("room"));
  EXPECT_EQ(s.frames_unusable, 10);
  EXPECT_LE(s.frames_tracked, 50);
  EXPECT_GE(s.frames_tracked, 40);
  EXPECT_EQ(s.Outcome(), "tracked");
}

}  // namespace
}  // namespace parallax
