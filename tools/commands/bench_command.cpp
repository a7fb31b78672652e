// parallax bench SUITE.yaml --out DIR [--jobs N] [--repeat K] [--baseline FILE] [--cache DIR]

#include <fmt/format.h>
#include <unistd.h>

#include <climits>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "tools/bench/plots.hpp"
#include "tools/bench/report.hpp"
#include "tools/commands/commands.hpp"
#include "tools/dataset/input_error.hpp"

namespace parallax::cli {
namespace {

struct BenchArgs {
  std::string suite;
  bench::BenchOptions options;
  std::string baseline;
  bool no_plots = false;
};

std::string SelfPath() {
  char buffer[PATH_MAX];
  const ssize_t n = readlink("/proc/self/exe", buffer, sizeof(buffer) - 1);
  if (n <= 0) throw std::runtime_error("bench: cannot find the parallax executable");
  return std::string(buffer, static_cast<std::size_t>(n));
}

void WriteFile(const std::string& path, const std::string& text) {
  const std::string partial = path + ".partial";
  {
    std::ofstream out(partial);
    out << text;
    if (!out) throw InputError(partial, "write failed");
  }
  std::filesystem::rename(partial, path);
}

int RunBenchCommand(BenchArgs& args, const std::string& invocation) {
  args.options.parallax_binary = SelfPath();
  args.options.progress = true;
  const bench::BenchResult result = bench::RunBench(args.suite, args.options);
  const std::filesystem::path out(args.options.out_dir);
  WriteFile((out / "report.json").string(), bench::ReportJson(result, invocation));
  const std::string md = bench::ReportMarkdown(result);
  WriteFile((out / "report.md").string(), md);
  if (!args.no_plots) bench::WritePlots(result, args.options.out_dir);
  std::fputs(md.c_str(), stdout);
  int failed = 0;
  for (const bench::RunRecord& r : result.runs) {
    if (r.Ok()) continue;
    ++failed;
    std::fprintf(
        stderr, "bench: %s (%s) failed: %s%s\n", r.sequence.c_str(), r.configuration.c_str(),
        r.exit_code != 0 ? fmt::format("exit {}", r.exit_code).c_str() : r.figures.error.c_str(),
        r.log_tail.empty() ? "" : ("\n" + r.log_tail).c_str());
  }
  if (!args.baseline.empty()) {
    const auto regressions = bench::CompareWithBaseline(result, args.baseline);
    for (const bench::Regression& r : regressions) {
      std::fprintf(stderr, "regression: %s (%s): %s\n", r.sequence.c_str(), r.configuration.c_str(),
                   r.what.c_str());
    }
    if (!regressions.empty()) return 3;
    std::fprintf(stderr, "bench: no regression against %s\n", args.baseline.c_str());
  }
  return failed > 0 ? 2 : 0;
}

}  // namespace

void AddBenchCommand(CLI::App& app, int* exit_code) {
  auto args = std::make_shared<BenchArgs>();
  CLI::App* cmd = app.add_subcommand(
      "bench", "Benchmark suite: runs, ATE/RPE/coverage/timing report, plots, regressions");
  cmd->add_option("suite", args->suite, "suite YAML (docs/benchmarks.md, 'The harness')")
      ->required();
  cmd->add_option("--out", args->options.out_dir, "output folder (report.json, report.md, plots)")
      ->required();
  cmd->add_option("--jobs", args->options.jobs, "runs in parallel")->check(CLI::PositiveNumber);
  cmd->add_option("--repeat", args->options.repeat, "runs per sequence (medians reported)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--baseline", args->baseline,
                  "earlier report.json: exit 3 and name the sequences that got worse");
  cmd->add_option("--cache", args->options.cache_dir,
                  "folder for rendered sequences (default: <out>/cache)");
  cmd->add_flag("--no-plots", args->no_plots, "skip the PNG plots");
  cmd->add_option("--cpus", args->options.cpus,
                  "pin every run (parallax and peers) to these CPUs, taskset syntax, e.g. 0");
  cmd->add_option_function<std::vector<std::string>>(
      "--peer",
      [args](const std::vector<std::string>& peers) {
        for (const std::string& p : peers) {
          const std::size_t eq = p.find('=');
          if (eq == std::string::npos || eq == 0 || eq + 1 == p.size()) {
            throw CLI::ValidationError("--peer", "expected NAME=COMMAND, got '" + p + "'");
          }
          args->options.peer_programs.push_back({p.substr(0, eq), p.substr(eq + 1)});
        }
      },
      "NAME=COMMAND: also run COMMAND DATASET OUT_DIR MAX_FRAMES on every sequence (it writes "
      "OUT_DIR/trajectory.txt) and compare time per frame (docs/benchmarks.md)");
  cmd->callback([args, exit_code, cmd] {
    std::string invocation = "parallax bench";
    for (const std::string& a : cmd->remaining(true)) invocation += " " + a;
    invocation += " " + args->suite + " --out " + args->options.out_dir +
                  fmt::format(" --jobs {} --repeat {}", args->options.jobs, args->options.repeat) +
                  (args->baseline.empty() ? "" : " --baseline " + args->baseline) +
                  (args->options.cpus.empty() ? "" : " --cpus " + args->options.cpus);
    for (const bench::PeerProgram& p : args->options.peer_programs) {
      invocation += " --peer " + p.name + "=" + p.command;
    }
    *exit_code = RunBenchCommand(*args, invocation);
  });
}

}  // namespace parallax::cli
