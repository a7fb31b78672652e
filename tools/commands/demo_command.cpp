// parallax demo: the README's main job. Renders a synthetic room sequence (hand-held motion)
// to a temporary folder, runs the pipeline on it and prints the accuracy.

#include <fmt/format.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>

#include "tools/commands/commands.hpp"
#include "tools/dataset/trajectory.hpp"
#include "tools/eval/evaluation.hpp"
#include "tools/run_pipeline.hpp"
#include "tools/synth/synthetic_sequence.hpp"

namespace parallax::cli {

void AddDemoCommand(CLI::App& app, int* exit_code) {
  auto frames = std::make_shared<int>(90);
  CLI::App* cmd = app.add_subcommand("demo", "Render a synthetic sequence, run it, print the ATE");
  cmd->add_option("--frames", *frames, "frames to render")->check(CLI::Range(10, 10000));
  cmd->callback([frames, exit_code] {
    const std::filesystem::path root =
        std::filesystem::temp_directory_path() / fmt::format("parallax_demo_{}", getpid());
    synth::SynthOptions synth_options;
    synth_options.scene = "room";
    synth_options.motion = "shake";
    synth_options.frames = *frames;
    std::fprintf(stderr, "rendering %d frames of the synthetic room...\n", *frames);
    synth::WriteSyntheticSequence(synth_options, (root / "sequence").string());
    RunOptions run;
    run.dataset = (root / "sequence").string();
    run.out_dir = (root / "output").string();
    run.progress = isatty(STDERR_FILENO) != 0;
    const RunSummary s = RunDataset(run);
    const EvaluationReport report =
        Evaluate(ReadTumTrajectory(run.out_dir + "/trajectory.txt"),
                 ReadTumTrajectory(run.dataset + "/groundtruth.txt"), {});
    std::printf(
        "%s",
        fmt::format("frames {}  tracked {} ({:.1f}%)  keyframes {}  {:.1f} frames/s\n"
                    "ATE RMSE {:.4f} m after Sim(3) alignment ({:.2f}% of the {:.2f} m path)\n"
                    "sequence: {}\noutputs:  {} (trajectory.txt, trajectory_online.txt, "
                    "keyframes.txt, map.ply, stats.json, frames.csv, run.json)\n",
                    s.frames, s.frames_tracked, 100.0 * s.frames_tracked / s.frames, s.keyframes,
                    s.fps, report.ate.rmse, report.ate_rmse_percent_of_path,
                    report.groundtruth_path_length, run.dataset, run.out_dir)
            .c_str());
    *exit_code = 0;
  });
}

}  // namespace parallax::cli
