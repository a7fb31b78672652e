// parallax eval <estimate> <groundtruth> [--align sim3|se3|none] [--max-dt S] [--json]
//   [--times F] [--estimate-times F] [--sensor F] [--frames DATASET] [--rpe-delta-m D]

#include <cstdio>
#include <filesystem>

#include "tools/commands/commands.hpp"
#include "tools/dataset/dataset_reader.hpp"
#include "tools/dataset/groundtruth_files.hpp"
#include "tools/eval/evaluation.hpp"

namespace parallax::cli {
namespace {

struct EvalArgs {
  std::string estimate;
  std::string groundtruth;
  std::string align = "sim3";
  double max_dt = 0.02;
  double rpe_delta_m = 0.0;
  std::string times;
  std::string estimate_times;
  std::string sensor;
  std::string frames;
  bool json = false;
};

void RunEval(const EvalArgs& args) {
  EvaluationOptions options;
  options.alignment = AlignmentModeFromString(args.align);
  options.max_dt = args.max_dt;
  options.rpe_delta_meters = args.rpe_delta_m;
  Trajectory groundtruth;
  if (std::filesystem::is_directory(args.groundtruth)) {
    DatasetGroundTruth gt = ReadDatasetGroundTruth(args.groundtruth);
    groundtruth = std::move(gt.poses);
    options.frame_timestamps = std::move(gt.frame_timestamps);
  } else {
    groundtruth = ReadTrajectoryFile({args.groundtruth, args.times, args.sensor});
  }
  // Only the image timestamps are wanted here: the folder need not have ground truth.
  if (!args.frames.empty()) options.frame_timestamps = OpenDataset(args.frames)->FrameTimestamps();
  const Trajectory estimate =
      ReadTrajectoryFile({args.estimate, args.estimate_times, "", args.times});
  const EvaluationReport report = Evaluate(estimate, groundtruth, options);
  const std::string text = args.json ? ReportToJson(report) + "\n" : FormatReport(report);
  std::fputs(text.c_str(), stdout);
}

}  // namespace

void AddEvalCommand(CLI::App& app, int* exit_code) {
  auto args = std::make_shared<EvalArgs>();
  CLI::App* cmd = app.add_subcommand(
      "eval",
      "Accuracy of a trajectory (ATE, RPE, KITTI) against TUM, KITTI or EuRoC ground truth");
  cmd->add_option("estimate", args->estimate, "estimated trajectory (TUM or KITTI format)")
      ->required();
  cmd->add_option("groundtruth", args->groundtruth,
                  "ground truth: a TUM, KITTI poses or EuRoC data.csv file, or a dataset folder")
      ->required();
  cmd->add_option("--align", args->align, "alignment before ATE")
      ->check(CLI::IsMember({"sim3", "se3", "none"}));
  cmd->add_option("--max-dt", args->max_dt, "association window, seconds")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--rpe-delta-m", args->rpe_delta_m,
                  "path step of the per-distance RPE (default: a tenth of the path)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--times", args->times, "KITTI times.txt of the ground-truth poses");
  cmd->add_option("--estimate-times", args->estimate_times,
                  "timestamps of a KITTI-format estimate (default: <estimate>.times.txt, else "
                  "the ground truth's)");
  cmd->add_option("--sensor", args->sensor, "EuRoC cam0/sensor.yaml (body-to-camera extrinsics)");
  cmd->add_option("--frames", args->frames,
                  "dataset folder whose image frames define coverage (automatic when the ground "
                  "truth is a dataset folder)");
  cmd->add_flag("--json", args->json, "machine-readable JSON on stdout");
  cmd->callback([args, exit_code] {
    RunEval(*args);
    *exit_code = 0;
  });
}

}  // namespace parallax::cli
