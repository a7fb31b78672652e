// parallax eval <estimate> <groundtruth> [--align sim3|se3|none] [--max-dt S] [--json]

#include <cstdio>

#include "tools/commands/commands.hpp"
#include "tools/dataset/trajectory.hpp"
#include "tools/eval/evaluation.hpp"

namespace parallax::cli {

void AddEvalCommand(CLI::App& app, int* exit_code) {
  struct Args {
    std::string estimate;
    std::string groundtruth;
    std::string align = "sim3";
    double max_dt = 0.02;
    bool json = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd =
      app.add_subcommand("eval", "Accuracy of a TUM-format trajectory (ATE, RPE, KITTI)");
  cmd->add_option("estimate", args->estimate, "estimated trajectory (TUM format)")->required();
  cmd->add_option("groundtruth", args->groundtruth, "ground truth (TUM format)")->required();
  cmd->add_option("--align", args->align, "alignment before ATE")
      ->check(CLI::IsMember({"sim3", "se3", "none"}));
  cmd->add_option("--max-dt", args->max_dt, "association window, seconds")
      ->check(CLI::PositiveNumber);
  cmd->add_flag("--json", args->json, "machine-readable JSON on stdout");
  cmd->callback([args, exit_code] {
    EvaluationOptions options;
    options.alignment = AlignmentModeFromString(args->align);
    options.max_dt = args->max_dt;
    const Trajectory estimate = ReadTumTrajectory(args->estimate);
    const Trajectory groundtruth = ReadTumTrajectory(args->groundtruth);
    const EvaluationReport report = Evaluate(estimate, groundtruth, options);
    const std::string text = args->json ? ReportToJson(report) + "\n" : FormatReport(report);
    std::fputs(text.c_str(), stdout);
    *exit_code = 0;
  });
}

}  // namespace parallax::cli
