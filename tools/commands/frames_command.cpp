// parallax frames <dataset> --out DIR [--max-frames N]: the frames as the engine sees them.

#include <cstdio>

#include "tools/commands/commands.hpp"
#include "tools/dataset/frame_export.hpp"

namespace parallax::cli {

void AddFramesCommand(CLI::App& app, int* exit_code) {
  struct Args {
    FrameExportOptions options;
    std::string format = "auto";
    std::string calib;
    bool no_photometric = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "frames",
      "Write the frames as the engine sees them (grey, undistorted to its pinhole camera), "
      "e.g. for another system to run on");
  cmd->add_option("dataset", args->options.dataset, "dataset folder or video file")->required();
  cmd->add_option("--out", args->options.out_dir, "output folder: images/, times.txt, camera.txt")
      ->required();
  cmd->add_option("--format", args->format, "auto|tum|monovo|euroc|kitti|images|video");
  cmd->add_option("--calib", args->calib, "calibration YAML (docs/calibration.md)");
  cmd->add_option("--max-frames", args->options.max_frames, "the first N frames (0: all)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--no-photometric", args->no_photometric,
                "do not apply the dataset's photometric calibration");
  cmd->callback([args, exit_code] {
    args->options.dataset_options.format = DatasetFormatFromString(args->format);
    args->options.dataset_options.calibration_file = args->calib;
    args->options.photometric = !args->no_photometric;
    const FrameExportSummary summary = ExportFrames(args->options);
    std::printf("wrote %d frames to %s (%d unreadable, skipped)\n", summary.frames,
                args->options.out_dir.c_str(), summary.unreadable);
    *exit_code = 0;
  });
}

}  // namespace parallax::cli
