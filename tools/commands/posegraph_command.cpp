// parallax posegraph IN.g2o --out OUT.g2o [--json] [--kernel none|huber|cauchy]
//   [--kernel-width W] [--max-iterations N] [--solver cholmod|dense]

#include <fmt/format.h>

#include <chrono>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "backend/pose_graph_optimizer.hpp"
#include "tools/commands/commands.hpp"
#include "tools/dataset/g2o_file.hpp"

namespace parallax::cli {
namespace {

struct PosegraphArgs {
  std::string input;
  std::string output;
  std::string kernel = "none";
  double kernel_width = 1.0;
  int max_iterations = 100;
  std::string solver = "cholmod";
  bool json = false;
};

RobustKernel KernelFromString(const std::string& name) {
  if (name == "huber") return RobustKernel::kHuber;
  if (name == "cauchy") return RobustKernel::kCauchy;
  return RobustKernel::kNone;
}

void RunPosegraph(const PosegraphArgs& args) {
  const auto read_start = std::chrono::steady_clock::now();
  G2oGraph g2o = ReadG2oFile(args.input);
  const double read_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - read_start)
          .count();
  PoseGraphOptimizerOptions options;
  options.optimize_scale = false;  // g2o SE(3) graphs
  options.kernel = KernelFromString(args.kernel);
  options.kernel_width = args.kernel_width;
  options.max_iterations = args.max_iterations;
  options.solver = args.solver == "dense" ? LinearSolverKind::kDense : LinearSolverKind::kCholmod;
  const PoseGraphSummary s = PoseGraphOptimizer(options).Optimize(&g2o.graph);
  if (!args.output.empty()) WriteG2oFile(args.output, g2o.graph);
  const nlohmann::json j = {
      {"input", args.input},
      {"output", args.output},
      {"vertices", g2o.graph.NumVertices()},
      {"edges", g2o.graph.Edges().size()},
      {"block_diagonal_information", g2o.block_diagonal_information},
      {"residual",
       "ceres pose_graph_3d: [R_m^T (R_i^T (t_j - t_i) - t_m); 2 vec(q_m^-1 q_i^-1 q_j)]"},
      {"initial_cost", s.initial_cost},
      {"final_cost", s.final_cost},
      {"final_cost_unrobustified", g2o.graph.Cost()},
      {"iterations", s.iterations},
      {"accepted_steps", s.accepted_steps},
      {"converged", s.converged},
      {"termination", s.termination},
      {"read_ms", read_ms},
      {"solve_ms", s.total_ms}};
  if (args.json) {
    std::fputs((j.dump(2) + "\n").c_str(), stdout);
    return;
  }
  std::fputs(fmt::format("{}: {} vertices, {} edges{}\n", args.input, g2o.graph.NumVertices(),
                         g2o.graph.Edges().size(),
                         g2o.block_diagonal_information > 0
                             ? fmt::format(" ({} information matrices not positive definite: "
                                           "block diagonal used)",
                                           g2o.block_diagonal_information)
                             : std::string())
                 .c_str(),
             stdout);
  std::fputs(fmt::format("initial cost {:.9g}\nfinal cost   {:.9g}\niterations   {} ({} "
                         "accepted), {}\nsolve time   {:.1f} ms\n",
                         s.initial_cost, s.final_cost, s.iterations, s.accepted_steps,
                         s.termination, s.total_ms)
                 .c_str(),
             stdout);
}

}  // namespace

void AddPosegraphCommand(CLI::App& app, int* exit_code) {
  auto args = std::make_shared<PosegraphArgs>();
  CLI::App* cmd = app.add_subcommand("posegraph", "Optimise a g2o 3-D pose graph (SE(3))");
  cmd->add_option("input", args->input, "g2o file (VERTEX_SE3:QUAT, EDGE_SE3:QUAT)")->required();
  cmd->add_option("--out", args->output, "optimised graph, g2o format");
  cmd->add_option("--kernel", args->kernel, "robust kernel")
      ->check(CLI::IsMember({"none", "huber", "cauchy"}));
  cmd->add_option("--kernel-width", args->kernel_width, "kernel width (Mahalanobis)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--max-iterations", args->max_iterations, "Levenberg-Marquardt iterations")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--solver", args->solver, "linear solver")
      ->check(CLI::IsMember({"cholmod", "dense"}));
  cmd->add_flag("--json", args->json, "machine-readable JSON on stdout");
  cmd->callback([args, exit_code] {
    RunPosegraph(*args);
    *exit_code = 0;
  });
}

}  // namespace parallax::cli
