#include "tools/dataset/frame_export.hpp"

#include <fmt/format.h>

#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <optional>

#include "core/check.hpp"
#include "core/undistorter.hpp"
#include "tools/dataset/frame_prefetcher.hpp"
#include "tools/dataset/image_file.hpp"
#include "tools/dataset/input_error.hpp"
#include "tools/dataset/opencv_image.hpp"
#include "tools/dataset/photometric_corrector.hpp"

namespace parallax {

FrameExportSummary ExportFrames(const FrameExportOptions& options) {
  CheckArgument(options.max_frames >= 0, "--max-frames must be >= 0");
  const auto reader = OpenDataset(options.dataset, options.dataset_options);
  const Undistorter undistorter(reader->GetCamera(), reader->SuggestedRectification());
  std::optional<PhotometricCorrector> photometric;
  if (const auto calibration = reader->Photometric(); calibration && options.photometric) {
    photometric.emplace(*calibration, reader->GetCamera().Width(), reader->GetCamera().Height());
  }
  const bool correct = photometric && photometric->Enabled();
  const std::filesystem::path out(options.out_dir);
  std::filesystem::create_directories(out / "images");
  std::ofstream times(out / "times.txt");
  if (!times) throw InputError((out / "times.txt").string(), "cannot open for writing");
  FramePrefetcher frames(reader.get(), &undistorter, 4, true, correct ? &*photometric : nullptr);
  FrameExportSummary summary;
  int seen = 0;
  while (options.max_frames == 0 || seen < options.max_frames) {
    const auto frame = frames.Next();
    if (!frame) break;
    ++seen;
    if (!frame->error.empty()) {
      ++summary.unreadable;
      continue;
    }
    const std::string name = fmt::format("{:06d}", frame->index);
    const std::string file = (out / "images" / (name + ".png")).string();
    WritePngFile(file, GreyMatView(frame->image), 1);
    times << name << ' ' << fmt::format("{:.6f}", frame->timestamp) << '\n';
    ++summary.frames;
  }
  const PinholeCamera& K = undistorter.OutputCamera();
  std::ofstream camera(out / "camera.txt");
  camera << fmt::format("{:.9g} {:.9g} {:.9g} {:.9g}\n{} {}\n", K.Fx(), K.Fy(), K.Cx(), K.Cy(),
                        K.Width(), K.Height());
  if (!times || !camera) throw InputError(options.out_dir, "write failed");
  return summary;
}

}  // namespace parallax
