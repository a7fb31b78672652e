// parallax info <dataset> [--format F] [--calib FILE]: what the readers see in a dataset.

#include <fmt/format.h>

#include <cstdio>

#include "tools/commands/commands.hpp"
#include "tools/dataset/dataset_reader.hpp"

namespace parallax::cli {

void AddInfoCommand(CLI::App& app, int* exit_code) {
  struct Args {
    std::string path;
    std::string format = "auto";
    std::string calib;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd =
      app.add_subcommand("info", "Describe a dataset: layout, camera, frames, ground truth");
  cmd->add_option("dataset", args->path, "dataset folder or video file")->required();
  cmd->add_option("--format", args->format, "auto|tum|monovo|euroc|kitti|images|video");
  cmd->add_option("--calib", args->calib, "calibration YAML (docs/calibration.md)");
  cmd->callback([args, exit_code] {
    DatasetOptions options;
    options.format = DatasetFormatFromString(args->format);
    options.calibration_file = args->calib;
    const auto reader = OpenDataset(args->path, options);
    std::string text = fmt::format("format       {}\ncamera       {}\nframes       {}\n",
                                   ToString(reader->Format()), reader->GetCamera().ToString(),
                                   reader->NumFrames());
    if (const auto gt = reader->GroundTruth()) {
      text += fmt::format("groundtruth  {} poses\n", gt->size());
    } else {
      text += "groundtruth  none\n";
    }
    if (const auto first = reader->Next()) {
      text += fmt::format("first frame  t={} {}x{} {}\n", first->timestamp, first->image.Width(),
                          first->image.Height(), first->source);
    }
    std::fputs(text.c_str(), stdout);
    *exit_code = 0;
  });
}

}  // namespace parallax::cli
