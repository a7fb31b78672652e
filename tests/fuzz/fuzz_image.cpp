// Image decoding as the readers do it (OpenCV behind the TUM reader), then the frame-quality
// gate and a pyramid of whatever decoded.
#include "core/frame_quality.hpp"
#include "core/image_pyramid.hpp"
#include "fuzz_input.hpp"
#include "tools/dataset/dataset_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace parallax;
  const auto root = fuzz::Scratch() / "image";
  fuzz::WriteInput("image/rgb/a.png", data, size);
  std::ofstream(root / "rgb.txt") << "0.0 rgb/a.png\n";
  std::ofstream(root / "calibration.yaml")
      << "model: pinhole\nwidth: 64\nheight: 48\nfx: 50\nfy: 50\ncx: 32\ncy: 24\n";
  fuzz::Accepts([&] {
    const auto reader = OpenDataset(root.string());
    if (const auto frame = reader->Next()) {
      AssessFrame(frame->image);
      const ImagePyramid pyramid(frame->image);
      (void)pyramid.NumLevels();
    }
  });
  return 0;
}
