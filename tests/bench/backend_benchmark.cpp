// Pose-graph optimisation cost: one Levenberg-Marquardt iteration on a 2,500-keyframe graph.

#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

#include "backend/pose_graph_optimizer.hpp"

namespace parallax {
namespace {

/// 2,500 keyframes on a 50 x 50 serpentine (each with its own scale), odometry between
/// consecutive ones and a neighbour edge to the keyframe beside it in the previous row:
/// ~5,000 edges, like sphere2500. Vertices start at the chained, noisy odometry.
PoseGraph SerpentineGraph(bool with_scale) {
  std::mt19937_64 rng(1);
  std::normal_distribution<double> noise(0.0, 0.01);
  const int side = 50;
  std::vector<Sim3d> truth;
  for (int k = 0; k < side * side; ++k) {
    const int row = k / side;
    const int col = row % 2 == 0 ? k % side : side - 1 - k % side;
    const double scale = with_scale ? std::exp(0.2 * std::sin(0.01 * k)) : 1.0;
    truth.emplace_back(scale, SO3d::Exp(Eigen::Vector3d(0.0, 0.1 * std::sin(0.05 * k), 0.0)),
                       Eigen::Vector3d(col, 0.0, row));
  }
  PoseGraph graph;
  const auto measured = [&](int i, int j) {
    Vector7d d;
    for (int r = 0; r < 7; ++r) d[r] = noise(rng);
    if (!with_scale) d[6] = 0.0;
    PoseGraphEdge e;
    e.i = i;
    e.j = j;
    e.S_i_j = truth[static_cast<std::size_t>(i)].Inverse() * truth[static_cast<std::size_t>(j)] *
              Sim3d::Exp(d);
    return e;
  };
  Sim3d chained = truth[0];
  graph.SetVertex(0, chained, true);
  for (int k = 1; k < side * side; ++k) {
    const PoseGraphEdge e = measured(k - 1, k);
    chained = chained * e.S_i_j;
    graph.SetVertex(k, chained);
    graph.AddEdge(e);
  }
  for (int k = side; k < side * side; ++k) {
    const int row = k / side;
    const int col_index = k % side;
    const int above = (row - 1) * side + (side - 1 - col_index);
    graph.AddEdge(measured(above, k));
  }
  return graph;
}

void RunOneIteration(benchmark::State& state, bool with_scale) {
  const PoseGraph graph = SerpentineGraph(with_scale);
  PoseGraphOptimizerOptions options;
  options.optimize_scale = with_scale;
  options.max_iterations = 1;
  const PoseGraphOptimizer optimizer(options);
  for (auto _ : state) {
    PoseGraph copy = graph;
    benchmark::DoNotOptimize(optimizer.Optimize(&copy).final_cost);
  }
  state.counters["edges"] = static_cast<double>(graph.Edges().size());
}

void BM_PoseGraphIterationSim3_2500(benchmark::State& state) { RunOneIteration(state, true); }
void BM_PoseGraphIterationSe3_2500(benchmark::State& state) { RunOneIteration(state, false); }

BENCHMARK(BM_PoseGraphIterationSim3_2500)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PoseGraphIterationSe3_2500)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace parallax

BENCHMARK_MAIN();
