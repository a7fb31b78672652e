#pragma once
// Levenberg-Marquardt on a Sim(3) (or SE(3)) pose graph with sparse Cholesky (CHOLMOD).
// Math: docs/math/pose_graph.md.

#include <string>
#include <vector>

#include "backend/block_sparse_cholesky.hpp"
#include "backend/pose_graph.hpp"

namespace parallax {

/// Robust kernel on the Mahalanobis length sqrt(r^T Omega r) of an edge residual.
enum class RobustKernel {
  kNone,
  kHuber,   ///< quadratic up to `kernel_width`, linear beyond
  kCauchy,  ///< rho(e) = w^2 log(1 + e / w^2): outliers lose almost all weight
};

struct PoseGraphOptimizerOptions {
  /// false: SE(3) graph (every vertex and measurement keeps scale 1; 6 DoF per vertex).
  bool optimize_scale = true;
  RobustKernel kernel = RobustKernel::kNone;
  /// Mahalanobis distance at which the kernel departs from the quadratic (sigma units).
  double kernel_width = 1.0;
  int max_iterations = 100;
  /// Stop when an accepted step lowers the cost by less than this fraction of it.
  double function_tolerance = 1e-10;
  /// Stop when max |gradient| falls below this.
  double gradient_tolerance = 1e-12;
  /// Stop when |dx| < parameter_tolerance * (|x| + parameter_tolerance) (x: tangent norm
  /// proxy, the sum of vertex translation norms and scale logs).
  double parameter_tolerance = 1e-12;
  /// Marquardt damping: H + lambda * diag(H); the first lambda and the floor of diag(H).
  double initial_lambda = 1e-5;
  double min_diagonal = 1e-6;
  LinearSolverKind solver = LinearSolverKind::kCholmod;

  void Check() const;
};

/// What one optimisation did.
struct PoseGraphSummary {
  double initial_cost = 0.0;  ///< robustified cost at the start (0.5 sum rho(r^T Omega r))
  double final_cost = 0.0;
  int iterations = 0;  ///< linear solves (accepted or not)
  int accepted_steps = 0;
  bool converged = false;   ///< a tolerance was met (not the iteration limit)
  std::string termination;  ///< which criterion ended it
  double total_ms = 0.0;
  std::vector<double> iteration_ms;
};

/// Optimises the graph in place. Fixed vertices are the gauge; with none fixed the vertex
/// with the smallest id is held (a free gauge makes the normal equations singular).
class PoseGraphOptimizer {
 public:
  explicit PoseGraphOptimizer(const PoseGraphOptimizerOptions& options = {});

  /// Starts from the graph's current poses (warm start) and writes the optimum back.
  /// Throws std::invalid_argument if the graph is not a valid SE(3) graph when
  /// optimize_scale is false (a vertex or measurement with scale != 1).
  PoseGraphSummary Optimize(PoseGraph* graph) const;

  /// Robust weight d rho / d e at e = r^T Omega r (1 in the quadratic region).
  double KernelWeight(double squared_error) const;
  /// rho(e) (e itself in the quadratic region).
  double KernelCost(double squared_error) const;

  const PoseGraphOptimizerOptions& Options() const { return options_; }

 private:
  PoseGraphOptimizerOptions options_;
};

}  // namespace parallax
