// g2o pose graphs, read and then optimised a few iterations (non-finite or degenerate graphs
// must be rejected or survive, never crash).
#include "backend/pose_graph_optimizer.hpp"
#include "fuzz_input.hpp"
#include "tools/dataset/g2o_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace parallax;
  const std::string path = fuzz::WriteInput("graph.g2o", data, size);
  fuzz::Accepts([&] {
    G2oGraph g = ReadG2oFile(path);
    if (g.graph.NumVertices() > 200) return;  // keep each input fast
    PoseGraphOptimizerOptions options;
    options.optimize_scale = false;
    options.max_iterations = 5;
    PoseGraphOptimizer(options).Optimize(&g.graph);
  });
  return 0;
}
