// parallax frames: the exported frames are exactly what `run` feeds the engine (undistorted to
// its pinhole camera), with their timestamps and that camera.

#include "tools/dataset/frame_export.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <sstream>

#include "core/undistorter.hpp"
#include "tests/tools/temp_dir.hpp"
#include "tools/dataset/dataset_reader.hpp"
#include "tools/dataset/image_file.hpp"
#include "tools/synth/synthetic_sequence.hpp"

namespace parallax {
namespace {

// Exports the first `n` frames of `dataset` and checks images, times and camera against the
// reader and undistorter `run` uses.
void ExpectExportMatchesTheEngineInput(const std::string& dataset, const std::string& out, int n) {
  FrameExportOptions options;
  options.dataset = dataset;
  options.out_dir = out;
  options.max_frames = n;
  const FrameExportSummary summary = ExportFrames(options);
  EXPECT_EQ(summary.frames, n);
  const auto reader = OpenDataset(dataset);
  const Undistorter undistorter(reader->GetCamera(), reader->SuggestedRectification());
  const PinholeCamera& K = undistorter.OutputCamera();
  std::ifstream camera(out + "/camera.txt");
  double fx = 0, fy = 0, cx = 0, cy = 0;
  int width = 0, height = 0;
  camera >> fx >> fy >> cx >> cy >> width >> height;
  EXPECT_NEAR(fx, K.Fx(), 1e-6 * K.Fx());
  EXPECT_NEAR(cy, K.Cy(), 1e-6 * K.Fx());
  EXPECT_EQ(width, K.Width());
  EXPECT_EQ(height, K.Height());
  std::ifstream times(out + "/times.txt");
  for (int k = 0; k < n; ++k) {
    const auto frame = reader->Next();
    ASSERT_TRUE(frame);
    std::string name;
    double t = 0.0;
    times >> name >> t;
    EXPECT_NEAR(t, frame->timestamp, 1e-6);
    std::string file = out;
    file += "/images/" + name;
    const cv::Mat written = ReadImageFile(file + ".png", ImageReadMode::kUnchanged);
    const ImageU8 expected = undistorter.Apply(frame->image);
    ASSERT_EQ(written.cols, expected.Width());
    ASSERT_EQ(written.rows, expected.Height());
    int differing = 0;
    for (int y = 0; y < written.rows; ++y) {
      for (int x = 0; x < written.cols; ++x)
        differing += written.at<std::uint8_t>(y, x) != expected(x, y);
    }
    EXPECT_EQ(differing, 0) << name;
  }
  std::string extra;
  EXPECT_FALSE(times >> extra) << "more than " << n << " frames";
}

TEST(FrameExport, WritesTheFramesTheEngineSees) {
  const test::TempDir dir;
  synth::SynthOptions options;
  options.frames = 8;
  options.width = 320;
  options.height = 240;
  options.layout = "tum_mono";
  synth::WriteSyntheticSequence(options, dir.File("render"));
  ExpectExportMatchesTheEngineInput(dir.File("render"), dir.File("pinhole"), 5);
  // Through a lens: the export is undistorted to the engine's (cropped) pinhole camera.
  std::ofstream(dir.File("render/camera.txt"), std::ios::trunc)
      << "RadTan 300 300 159.5 119.5 -0.2 0.05 0 0\n320 240\ncrop\n320 240\n";
  ExpectExportMatchesTheEngineInput(dir.File("render"), dir.File("lens"), 3);
  std::ifstream camera(dir.File("lens/camera.txt"));
  double fx = 0.0;
  camera >> fx;
  EXPECT_NE(fx, 300.0);  // the crop changed the focal length
}

}  // namespace
}  // namespace parallax
