// Writes a dataset's raw (still distorted) grey frames as a frame folder for the C API
// tests and example (tools/capi/examples/frame_folder.h): camera.txt, frames.txt, PGMs.
// The frames are exactly what `parallax run` reads, so both see the same input.
//   capi_export_frames DATASET OUT_DIR

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "tools/dataset/dataset_reader.hpp"
#include "tools/dataset/trajectory.hpp"

int main(int argc, char** argv) {
  using namespace parallax;
  if (argc != 3) {
    std::fprintf(stderr, "usage: capi_export_frames DATASET OUT_DIR\n");
    return 2;
  }
  try {
    const auto reader = OpenDataset(argv[1]);
    const Camera& camera = reader->GetCamera();
    const UndistorterOptions rectification = reader->SuggestedRectification();
    if (rectification.mode == UndistortMode::kExplicit || rectification.output_width != 0 ||
        rectification.output_height != 0) {
      std::fprintf(stderr, "%s: its rectification has no px_camera equivalent\n", argv[1]);
      return 1;
    }
    const std::filesystem::path out(argv[2]);
    std::filesystem::create_directories(out);
    std::ofstream camera_file(out / "camera.txt");
    camera_file.precision(17);
    camera_file << static_cast<int>(camera.Model()) << ' ' << camera.Width() << ' '
                << camera.Height() << ' ' << camera.Intrinsics().Fx() << ' '
                << camera.Intrinsics().Fy() << ' ' << camera.Intrinsics().Cx() << ' '
                << camera.Intrinsics().Cy();
    for (std::size_t k = 0; k < 5; ++k) {
      camera_file << ' ' << (k < camera.Distortion().size() ? camera.Distortion()[k] : 0.0);
    }
    camera_file << ' ' << (rectification.mode == UndistortMode::kFull ? 1 : 0) << '\n';
    std::ofstream frames(out / "frames.txt");
    while (const auto frame = reader->Next()) {
      char name[32];
      std::snprintf(name, sizeof name, "%06zu.pgm", frame->index);
      std::ofstream pgm(out / name, std::ios::binary);
      pgm << "P5\n" << frame->image.Width() << ' ' << frame->image.Height() << "\n255\n";
      pgm.write(reinterpret_cast<const char*>(frame->image.Data()),
                static_cast<std::streamsize>(frame->image.NumPixels()));
      frames << FormatTimestamp(frame->timestamp) << ' ' << name << '\n';
      if (!pgm) throw std::runtime_error(std::string(name) + ": write failed");
    }
    if (!frames || !camera_file) throw std::runtime_error(std::string(argv[2]) + ": write failed");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "capi_export_frames: %s\n", e.what());
    return 1;
  }
  return 0;
}
