#pragma once
// PNG plots of a benchmark run with gnuplot (Debian's gnuplot-nox): per run the trajectory
// from above against the ground truth, ATE over time and per-stage time per frame; a summary
// chart across runs.

#include <string>
#include <vector>

#include "tools/bench/bench_runner.hpp"

namespace parallax::bench {

/// Writes <out_dir>/plots/...; returns the PNG files written (empty, with a warning on
/// stderr, when gnuplot is not installed).
std::vector<std::string> WritePlots(const BenchResult& result, const std::string& out_dir);

}  // namespace parallax::bench
