// Dataset readers on the shared real clips (skipped when absent) and on small fixtures of
// every layout, including malformed input.

#include "tools/dataset/dataset_reader.hpp"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "tests/tools/temp_dir.hpp"
#include "tools/dataset/calibration_yaml.hpp"
#include "tools/dataset/file_list_reader.hpp"
#include "tools/dataset/image_file.hpp"
#include "tools/dataset/input_error.hpp"

namespace parallax {
namespace {

using test::SharedDataDir;
using test::TempDir;

void WriteGreyPng(const std::string& path, int w, int h, int value) {
  std::filesystem::create_directories(std::filesystem::path(path).parent_path());
  WritePngFile(path, cv::Mat(h, w, CV_8UC1, cv::Scalar(value)));
}

std::string PinholeYaml(int w, int h, const std::string& extra = "") {
  return "model: pinhole\nwidth: " + std::to_string(w) + "\nheight: " + std::to_string(h) +
         "\nfx: 100\nfy: 100\ncx: 15.5\ncy: 11.5\n" + extra;
}

TEST(SharedData, TumFreiburg1Clip) {
  if (SharedDataDir().empty())
    GTEST_SKIP() << "../shared/data is absent; real-clip reader test skipped";
  const std::string path = SharedDataDir() + "/rgbd_dataset_freiburg1_xyz_first37";
  EXPECT_EQ(DetectDatasetFormat(path), DatasetFormat::kTumRgbd);
  const auto reader = OpenDataset(path);
  EXPECT_EQ(reader->NumFrames(), 37u);
  const Camera& camera = reader->GetCamera();
  EXPECT_EQ(camera.Model(), CameraModel::kRadTan);
  EXPECT_DOUBLE_EQ(camera.Intrinsics().Fx(), 517.306408);
  EXPECT_DOUBLE_EQ(camera.Intrinsics().Cy(), 255.313989);
  EXPECT_DOUBLE_EQ(camera.Distortion()[4], 1.163314);
  const auto gt = reader->GroundTruth();
  ASSERT_TRUE(gt.has_value());
  EXPECT_EQ(gt->size(), 3000u);
  std::size_t count = 0;
  double last = 0.0;
  while (auto frame = reader->Next()) {
    if (count == 0) {
      EXPECT_DOUBLE_EQ(frame->timestamp, 1305031102.175304);
    }
    EXPECT_EQ(frame->image.Width(), 640);
    EXPECT_GT(frame->timestamp, last);
    last = frame->timestamp;
    ++count;
  }
  EXPECT_EQ(count, 37u);
}

TEST(SharedData, KittiClip) {
  if (SharedDataDir().empty())
    GTEST_SKIP() << "../shared/data is absent; real-clip reader test skipped";
  const std::string path = SharedDataDir() + "/kitti_odometry_07_first160";
  EXPECT_EQ(DetectDatasetFormat(path), DatasetFormat::kKitti);
  const auto reader = OpenDataset(path);
  EXPECT_EQ(reader->NumFrames(), 160u);
  const PinholeCamera& K = reader->GetCamera().Intrinsics();
  EXPECT_EQ(reader->GetCamera().Model(), CameraModel::kPinhole);
  EXPECT_EQ(K.Width(), 1226);
  EXPECT_EQ(K.Height(), 370);
  EXPECT_DOUBLE_EQ(K.Fx(), 707.0912);
  EXPECT_DOUBLE_EQ(K.Cx(), 601.8873);
  EXPECT_DOUBLE_EQ(K.Cy(), 183.1104);
  const auto gt = reader->GroundTruth();
  ASSERT_TRUE(gt.has_value());
  ASSERT_EQ(gt->size(), 160u);
  EXPECT_LT(gt->front().T_w_c.Translation().norm(), 1e-9);  // first camera = identity
  EXPECT_NEAR((*gt)[1].timestamp, 0.1038752, 1e-9);
  const auto frame = reader->Next();
  ASSERT_TRUE(frame.has_value());
  EXPECT_EQ(frame->image.Height(), 370);
}

TEST(TumReader, UsesCalibrationFileAndRejectsBadInput) {
  TempDir dir;
  dir.Write("calibration.yaml", PinholeYaml(32, 24));
  dir.Write("rgb.txt", "# comment\n1.0 rgb/a.png\n2.0 rgb/b.png\n");
  WriteGreyPng(dir.File("rgb/a.png"), 32, 24, 10);
  WriteGreyPng(dir.File("rgb/b.png"), 32, 24, 20);
  auto reader = OpenDataset(dir.Path().string());
  EXPECT_EQ(reader->NumFrames(), 2u);
  EXPECT_EQ(reader->Next()->image(0, 0), 10);
  EXPECT_EQ(reader->Next()->image(0, 0), 20);
  EXPECT_FALSE(reader->Next().has_value());
  EXPECT_FALSE(reader->GroundTruth().has_value());

  // Wrong image size names the image.
  WriteGreyPng(dir.File("rgb/b.png"), 16, 24, 20);
  reader = OpenDataset(dir.Path().string());
  reader->Next();
  try {
    reader->Next();
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("b.png"), std::string::npos) << e.what();
  }
  // Corrupt PNG.
  dir.Write("rgb/b.png", "not a png");
  reader = OpenDataset(dir.Path().string());
  reader->Next();
  EXPECT_THROW(reader->Next(), InputError);
  // Non-increasing timestamps name rgb.txt and the line.
  dir.Write("rgb.txt", "2.0 rgb/a.png\n1.0 rgb/b.png\n");
  try {
    OpenDataset(dir.Path().string());
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.Line(), 2);
    EXPECT_NE(e.File().find("rgb.txt"), std::string::npos);
  }
  // Bad line.
  dir.Write("rgb.txt", "1.0 rgb/a.png\nabc rgb/b.png\n");
  EXPECT_THROW(OpenDataset(dir.Path().string()), InputError);
  // Calibration with fx = 0 names the calibration file.
  dir.Write("rgb.txt", "1.0 rgb/a.png\n");
  dir.Write("calibration.yaml",
            "model: pinhole\nwidth: 32\nheight: 24\nfx: 0\nfy: 100\ncx: 1\ncy: 1\n");
  try {
    OpenDataset(dir.Path().string());
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("calibration.yaml"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("fx"), std::string::npos) << e.what();
  }
  // A focal length no lens has (it used to crash the depth filter) names the file too.
  dir.Write("calibration.yaml",
            "model: pinhole\nwidth: 32\nheight: 24\nfx: 1e100\nfy: 1e100\ncx: 16\ncy: 12\n");
  try {
    OpenDataset(dir.Path().string());
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("calibration.yaml"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("implausible calibration: fx = 1e+100"), std::string::npos)
        << e.what();
  }
}

TEST(DatasetDetection, MissingOrUnknownLayoutsAreReported) {
  TempDir dir;
  EXPECT_THROW(OpenDataset(dir.File("nope")), InputError);
  try {
    OpenDataset(dir.Path().string());  // empty folder
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot recognise"), std::string::npos);
  }
  EXPECT_THROW(DatasetFormatFromString("rosbag"), std::invalid_argument);
}

TEST(CalibrationYaml, RoundTripAndLineNumbers) {
  TempDir dir;
  const Camera camera(CameraModel::kRadTan, 640, 480, 517.3, 516.5, 318.6, 255.3,
                      {0.26, -0.95, -0.005, 0.0026, 1.16});
  WriteCalibrationYaml(dir.File("c.yaml"), camera, 30.0);
  const CalibrationFile back = ReadCalibrationYaml(dir.File("c.yaml"));
  EXPECT_EQ(back.camera.Model(), CameraModel::kRadTan);
  EXPECT_EQ(back.camera.Distortion(), camera.Distortion());
  EXPECT_DOUBLE_EQ(back.camera.Intrinsics().Fx(), 517.3);
  EXPECT_EQ(back.fps, 30.0);
  try {
    ReadCalibrationYaml(dir.Write("bad.yaml", "model: radtan\nwidth: 640\nheight: 480\nfx: abc\n"));
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.Line(), 4) << e.what();
  }
  EXPECT_THROW(
      ReadCalibrationYaml(dir.Write("nan.yaml", PinholeYaml(32, 24, "distortion: [.nan]\n"))),
      InputError);
  EXPECT_THROW(ReadCalibrationYaml(dir.Write("model.yaml", "model: kannala\nwidth: 1\n")),
               InputError);
  EXPECT_THROW(ReadCalibrationYaml(dir.Write("syntax.yaml", "model: [pinhole\n")), InputError);
}

TEST(EurocReader, ReadsSensorYamlAndTransformsGroundTruth) {
  TempDir dir;
  dir.Write(
      "mav0/cam0/sensor.yaml",
      "%YAML:1.0\nsensor_type: camera\nT_BS:\n  cols: 4\n  rows: 4\n  data: [1.0, 0.0, 0.0, 0.5,\n"
      "         0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0]\nrate_hz: 20\n"
      "resolution: [32, 24]\ncamera_model: pinhole\nintrinsics: [100.0, 101.0, 15.5, 11.5]\n"
      "distortion_model: radial-tangential\ndistortion_coefficients: [-0.28, 0.07, 0.0002, "
      "1.8e-05]\n");
  dir.Write("mav0/cam0/data.csv",
            "#timestamp [ns],filename\n1403636579763555584,a.png\n1403636579813555456,b.png\n");
  WriteGreyPng(dir.File("mav0/cam0/data/a.png"), 32, 24, 1);
  WriteGreyPng(dir.File("mav0/cam0/data/b.png"), 32, 24, 2);
  dir.Write(
      "mav0/state_groundtruth_estimate0/data.csv",
      "#timestamp, p_x, p_y, p_z, q_w, q_x, q_y, q_z, ...\n"
      "1403636579763555584,1,2,3,0.7071067811865476,0,0,0.7071067811865476,0,0,0,0,0,0,0,0,0\n");
  const auto reader = OpenDataset(dir.Path().string());
  EXPECT_EQ(reader->Format(), DatasetFormat::kEuroc);
  EXPECT_EQ(reader->GetCamera().Model(), CameraModel::kRadTan);
  EXPECT_EQ(reader->GetCamera().Distortion().size(), 5u);
  EXPECT_NEAR(reader->Next()->timestamp, 1403636579.763555584, 1e-6);
  const auto gt = reader->GroundTruth();
  ASSERT_EQ(gt->size(), 1u);
  // T_W_C = T_W_B T_B_S: body rotated 90 deg about z, camera 0.5 m along body x -> world y.
  EXPECT_TRUE(gt->front().T_w_c.Translation().isApprox(Eigen::Vector3d(1, 2.5, 3), 1e-9));
}

TEST(TumMonoReader, RelativeFovCameraAndExposures) {
  TempDir dir;
  dir.Write("camera.txt", "0.5 0.6 0.5 0.5 0.9\n32 24\ncrop\n32 24\n");
  dir.Write("times.txt", "00000 1.5 10.0\n00001 1.6 12.5\n");
  WriteGreyPng(dir.File("images/00000.png"), 32, 24, 1);
  WriteGreyPng(dir.File("images/00001.png"), 32, 24, 2);
  const auto reader = OpenDataset(dir.Path().string());
  EXPECT_EQ(reader->Format(), DatasetFormat::kTumMono);
  const PinholeCamera& K = reader->GetCamera().Intrinsics();
  EXPECT_EQ(reader->GetCamera().Model(), CameraModel::kFov);
  EXPECT_DOUBLE_EQ(K.Fx(), 16.0);  // 0.5 * 32
  EXPECT_DOUBLE_EQ(K.Cx(), 15.5);  // 0.5 * 32 - 0.5
  const auto frame = reader->Next();
  EXPECT_EQ(frame->exposure_ms, 10.0);
  EXPECT_EQ(reader->SuggestedRectification().mode, UndistortMode::kCrop);
  dir.Write("times.txt", "00000 1.5 10.0\n");
  EXPECT_THROW(OpenDataset(dir.Path().string()), InputError);  // count mismatch
  // An image size beyond int (found by fuzz_dataset: it was undefined behaviour) is named.
  dir.Write("times.txt", "00000 1.5 10.0\n00001 1.6 12.5\n");
  dir.Write("camera.txt", "0.5 0.6 0.5 0.5 0.9\n1.7e23 24\ncrop\n32 24\n");
  try {
    OpenDataset(dir.Path().string());
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.Line(), 2) << e.what();
    EXPECT_NE(std::string(e.what()).find("image width"), std::string::npos) << e.what();
  }
}

TEST(ImageFolderReader, NaturalOrderAndFpsTimestamps) {
  TempDir dir;
  dir.Write("calibration.yaml", PinholeYaml(32, 24, "fps: 10\n"));
  for (const int i : {1, 2, 10})
    WriteGreyPng(dir.File("img" + std::to_string(i) + ".png"), 32, 24, i);
  const auto reader = OpenDataset(dir.Path().string());
  EXPECT_EQ(reader->Format(), DatasetFormat::kImages);
  std::vector<int> values;
  std::vector<double> times;
  while (auto f = reader->Next()) {
    values.push_back(f->image(0, 0));
    times.push_back(f->timestamp);
  }
  EXPECT_EQ(values, (std::vector<int>{1, 2, 10}));
  EXPECT_DOUBLE_EQ(times[2], 0.2);
  dir.Write("calibration.yaml", PinholeYaml(32, 24));
  EXPECT_THROW(OpenDataset(dir.Path().string()), InputError);  // neither times.txt nor fps
}

}  // namespace
}  // namespace parallax

namespace parallax {
namespace {

// fuzz_image: a file that starts like a PGM but carries DICOM's "DICM" at byte 128 went to
// OpenCV's GDCM decoder, which allocated 3.8 GB. It is refused before any decoder sees it.
TEST(ReadGreyImage, ADicomFileIsRefusedWhateverItsFirstBytes) {
  const test::TempDir dir;
  std::string bytes = "P2\n2 2\n255\n1 2 3 4\n";
  bytes.resize(128, ' ');
  bytes += "DICM";
  bytes.resize(160, '\0');
  const std::string path = dir.Write("frame.pgm", bytes);
  try {
    ReadGreyImage(path);
    FAIL() << "a DICOM file was decoded";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("DICOM"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  // The same PGM without the DICOM signature is read.
  const std::string plain = dir.Write("plain.pgm", "P2\n2 2\n255\n1 2 3 4\n");
  EXPECT_EQ(ReadGreyImage(plain).Width(), 2);
}

}  // namespace
}  // namespace parallax
