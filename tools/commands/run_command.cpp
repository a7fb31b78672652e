// parallax run <dataset> [--format F] [--calib FILE] [--config FILE] [--out DIR]
//              [--max-frames N] [--first-frame N] [--no-loop-closure] [--save-map FILE]
//              [--load-map FILE]

#include <fmt/format.h>
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstdio>

#include "tools/commands/commands.hpp"
#include "tools/config_yaml.hpp"
#include "tools/run_pipeline.hpp"

namespace parallax::cli {
namespace {

// Set by SIGINT/SIGTERM; the run stops between frames and writes what it has.
std::atomic<bool> g_stop_requested{false};

extern "C" void RequestStop(int /*signal*/) { g_stop_requested.store(true); }

}  // namespace

void AddRunCommand(CLI::App& app, int* exit_code) {
  auto options = std::make_shared<RunOptions>();
  auto format = std::make_shared<std::string>("auto");
  auto realtime = std::make_shared<bool>(false);
  auto config = std::make_shared<std::vector<std::string>>();
  CLI::App* cmd = app.add_subcommand("run", "Run visual odometry on a dataset");
  cmd->add_option("dataset", options->dataset, "dataset folder or video file")->required();
  cmd->add_option("--format", *format, "auto|tum|monovo|euroc|kitti|images|video");
  cmd->add_option("--calib", options->dataset_options.calibration_file,
                  "calibration YAML (docs/calibration.md)");
  cmd->add_option("--out", options->out_dir, "output folder (created)");
  cmd->add_option("--max-frames", options->max_frames, "stop after N frames (0: all)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--config", *config,
                  "pipeline options, YAML (docs/configuration.md); several are applied in order");
  cmd->add_flag("--realtime", *realtime,
                "real-time mode: tracking on this thread, mapping on another (docs/realtime.md)");
  cmd->add_option("--rate", options->rate,
                  "--realtime: play frames at R x their timestamps (1: real time; 0: as fast as "
                  "tracking goes); frames arriving while tracking is busy are dropped")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--fatal-unreadable", options->fatal_unreadable,
                "an unreadable image ends the run (default: skipped and reported)");
  cmd->add_flag("--no-photometric{false}", options->photometric,
                "ignore the dataset's photometric calibration (TUM monoVO pcalib.txt, "
                "vignette.png; applied by default)");
  auto trajectory_format = std::make_shared<std::string>("tum");
  cmd->add_option("--trajectory-format", *trajectory_format,
                  "trajectory files as tum, or kitti (+ <name>.times.txt)")
      ->check(CLI::IsMember({"tum", "kitti"}));
  cmd->add_option("--first-frame", options->first_frame,
                  "skip the dataset's frames before this index")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--save-map", options->save_map,
                  "write the map to FILE at the end (docs/map_files.md)");
  cmd->add_option("--load-map", options->load_map,
                  "start on the map in FILE: frames are relocalised on it and continue in its "
                  "world frame");
  auto no_loop_closure = std::make_shared<bool>(false);
  cmd->add_flag("--no-loop-closure", *no_loop_closure,
                "disable place recognition and loop closure (on by default)");
  cmd->callback([options, format, realtime, config, trajectory_format, no_loop_closure, exit_code] {
    options->trajectory_format = *trajectory_format == "kitti"
                                     ? RunOptions::TrajectoryFormat::kKitti
                                     : RunOptions::TrajectoryFormat::kTum;
    for (const std::string& file : *config) ApplyConfigYaml(file, &options->system);
    options->system.realtime.enabled = *realtime;
    if (*no_loop_closure) options->system.loop_closure.enabled = false;
    options->dataset_options.format = DatasetFormatFromString(*format);
    options->progress = isatty(STDERR_FILENO) != 0;
    options->stop = &g_stop_requested;
    std::signal(SIGINT, RequestStop);
    std::signal(SIGTERM, RequestStop);
    const RunSummary s = RunDataset(*options);
    std::signal(SIGINT, SIG_DFL);
    std::signal(SIGTERM, SIG_DFL);
    std::printf(
        "%s", fmt::format(
                  "{} frames, {} tracked ({:.1f}%), {} keyframes, {:.1f} frames/s; outputs in {}\n",
                  s.frames, s.frames_tracked, 100.0 * s.frames_tracked / s.frames, s.keyframes,
                  s.fps, options->out_dir)
                  .c_str());
    // Exit codes (docs/cli.md): 0 ran and posed frames, 4 ran and posed none, 130
    // interrupted (the outputs hold the frames processed until then).
    if (s.status == "interrupted") {
      std::fprintf(stderr, "parallax: interrupted after %d frames; partial outputs in %s\n",
                   s.frames, options->out_dir.c_str());
      *exit_code = 130;
      return;
    }
    if (s.frames_tracked == 0) {
      std::fprintf(stderr,
                   "parallax: no frame got a pose (%d of %d unusable: blank, dark, blown out or "
                   "noise); outputs are empty\n",
                   s.frames_unusable, s.frames);
      *exit_code = 4;
      return;
    }
    if (2 * s.frames_tracked < s.frames) {
      std::fprintf(stderr, "parallax: warning: only %d of %d frames got a pose (%d unusable)\n",
                   s.frames_tracked, s.frames, s.frames_unusable);
    }
    *exit_code = 0;
  });
}

}  // namespace parallax::cli
