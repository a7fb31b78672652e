// Dataset layouts' text files: the first byte picks the file (TUM rgb.txt, KITTI times.txt and
// calib.txt, EuRoC data.csv, monoVO times.txt and camera.txt), the rest is its content; the
// dataset is then opened and its first frames and ground truth read.
#include <opencv2/core.hpp>

#include "fuzz_input.hpp"
#include "tools/dataset/dataset_reader.hpp"
#include "tools/dataset/image_file.hpp"

namespace {

void WritePng(const std::filesystem::path& path) {
  // A valid 16x12 image, so that the list files are what gets exercised.
  std::filesystem::create_directories(path.parent_path());
  parallax::WritePngFile(path.string(), cv::Mat(12, 16, CV_8UC1, cv::Scalar(90)));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace parallax;
  if (size < 1) return 0;
  const int layout = data[0] % 6;
  const auto root = fuzz::Scratch() / ("layout" + std::to_string(layout));
  std::filesystem::remove_all(root);
  const char* calib = "model: pinhole\nwidth: 16\nheight: 12\nfx: 12\nfy: 12\ncx: 8\ncy: 6\n";
  switch (layout) {
    case 0:
      fuzz::WriteInput("layout0/rgb.txt", data + 1, size - 1);
      std::ofstream(root / "calibration.yaml") << calib;
      WritePng(root / "rgb" / "a.png");
      break;
    case 1:
      fuzz::WriteInput("layout1/sequences/00/times.txt", data + 1, size - 1);
      std::ofstream(root / "sequences/00/calib.txt") << "P0: 12 0 8 0 0 12 6 0 0 0 1 0\n";
      WritePng(root / "sequences/00/image_0/000000.png");
      break;
    case 2:
      std::filesystem::create_directories(root / "sequences/00");
      fuzz::WriteInput("layout2/sequences/00/calib.txt", data + 1, size - 1);
      std::ofstream(root / "sequences/00/times.txt") << "0\n";
      WritePng(root / "sequences/00/image_0/000000.png");
      break;
    case 3:
      fuzz::WriteInput("layout3/mav0/cam0/data.csv", data + 1, size - 1);
      std::ofstream(root / "calibration.yaml") << calib;
      WritePng(root / "mav0/cam0/data/0.png");
      break;
    case 4:
      fuzz::WriteInput("layout4/times.txt", data + 1, size - 1);
      std::ofstream(root / "camera.txt") << "Pinhole 0.75 1 0.5 0.5 0\n16 12\ncrop\n16 12\n";
      WritePng(root / "images/00000.png");
      break;
    default:
      fuzz::WriteInput("layout5/camera.txt", data + 1, size - 1);
      std::ofstream(root / "times.txt") << "00000 0.0 10.0\n";
      WritePng(root / "images/00000.png");
      break;
  }
  fuzz::Accepts([&] {
    const auto reader = OpenDataset(layout == 3 ? (root / "mav0").string() : root.string());
    for (int k = 0; k < 3 && reader->Next(); ++k) {
    }
    reader->GroundTruth();
  });
  return 0;
}
