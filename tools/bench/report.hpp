#pragma once
// The harness's outputs: report.json (every figure, the exact commands, commit, options and
// machine), report.md (the table docs/benchmarks.md embeds), and the baseline comparison.

#include <string>
#include <vector>

#include "tools/bench/bench_runner.hpp"

namespace parallax::bench {

/// report.json as a string (keys: docs/benchmarks.md, "The harness").
std::string ReportJson(const BenchResult& result, const std::string& invocation);
/// report.md: one table row per run, peers as extra columns.
std::string ReportMarkdown(const BenchResult& result);

/// A run that got worse than the baseline beyond its sequence's tolerance.
struct Regression {
  std::string sequence;
  std::string configuration;
  std::string what;  ///< e.g. "ATE 0.0060 -> 0.0090 m (+50%, tolerance 10% or 0.0001 m)"
};

/// Compares with an earlier report.json (runs matched by sequence and configuration). Runs
/// missing from the baseline are not compared; a run that failed now, or lost its
/// evaluation, is a regression. Throws InputError for an unreadable baseline.
std::vector<Regression> CompareWithBaseline(const BenchResult& result,
                                            const std::string& baseline_file);

}  // namespace parallax::bench
