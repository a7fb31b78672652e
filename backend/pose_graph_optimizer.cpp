#include "backend/pose_graph_optimizer.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <stdexcept>

#include "core/check.hpp"
#include "core/stopwatch.hpp"

namespace parallax {
namespace {

using Clock = StageClock;

/// The graph flattened for one optimisation: vertices by position, free ones with a block.
struct Problem {
  std::vector<std::int64_t> ids;
  std::vector<int> block;  ///< block index, -1 for a fixed vertex
  std::vector<Sim3d> poses;
  struct Edge {
    int vi = 0, vj = 0;
    int slot = -1;  ///< slot of the (min, max) off-diagonal block, -1 when not both free
    const PoseGraphEdge* edge = nullptr;
  };
  std::vector<Edge> edges;
  int num_blocks = 0;
};

Problem Flatten(const PoseGraph& graph) {
  Problem p;
  p.ids = graph.VertexIds();
  std::map<std::int64_t, int> position;
  bool any_fixed = false;
  for (std::size_t v = 0; v < p.ids.size(); ++v) {
    position[p.ids[v]] = static_cast<int>(v);
    p.poses.push_back(graph.Pose(p.ids[v]));
    any_fixed = any_fixed || graph.IsFixed(p.ids[v]);
  }
  for (std::size_t v = 0; v < p.ids.size(); ++v) {
    const bool fixed = graph.IsFixed(p.ids[v]) || (!any_fixed && v == 0);
    p.block.push_back(fixed ? -1 : p.num_blocks++);
  }
  for (const PoseGraphEdge& e : graph.Edges()) {
    p.edges.push_back({position.at(e.i), position.at(e.j), -1, &e});
  }
  return p;
}

BlockSparseSymmetric MakePattern(Problem* p, int block_size) {
  std::vector<std::pair<int, int>> pairs;
  for (const Problem::Edge& e : p->edges) {
    const int bi = p->block[static_cast<std::size_t>(e.vi)];
    const int bj = p->block[static_cast<std::size_t>(e.vj)];
    if (bi >= 0 && bj >= 0) pairs.emplace_back(bi, bj);
  }
  BlockSparseSymmetric H(p->num_blocks, block_size, pairs);
  for (Problem::Edge& e : p->edges) {
    const int bi = p->block[static_cast<std::size_t>(e.vi)];
    const int bj = p->block[static_cast<std::size_t>(e.vj)];
    if (bi >= 0 && bj >= 0) e.slot = H.Slot(std::min(bi, bj), std::max(bi, bj));
  }
  return H;
}

/// Adds M to block (r, c) of H (r <= c; on the diagonal only the upper triangle is stored).
template <int B>
void AddBlock(BlockSparseSymmetric* H, int r, int c, int slot,
              const Eigen::Matrix<double, B, B>& M) {
  for (int k = 0; k < B; ++k) {
    const int rows = r == c ? k + 1 : B;
    for (int i = 0; i < rows; ++i) H->Entry(c, slot, i, k) += M(i, k);
  }
}

class Solver {
 public:
  Solver(const PoseGraphOptimizer& optimizer, Problem* problem)
      : optimizer_(optimizer), p_(*problem) {}

  double Cost(const std::vector<Sim3d>& poses) const {
    double cost = 0.0;
    for (const Problem::Edge& e : p_.edges) {
      const Vector7d r = EdgeError(e.edge->S_i_j, poses[static_cast<std::size_t>(e.vi)],
                                   poses[static_cast<std::size_t>(e.vj)]);
      const double squared = r.dot(e.edge->information * r);
      cost += 0.5 * (e.edge->robust ? optimizer_.KernelCost(squared) : squared);
    }
    return cost;
  }

  /// Normal equations J^T W J and gradient J^T W r at `poses` (Gauss-Newton, IRLS weights).
  template <int B>
  void Assemble(const std::vector<Sim3d>& poses, BlockSparseSymmetric* H,
                Eigen::VectorXd* g) const {
    using MatB = Eigen::Matrix<double, B, B>;
    H->SetZero();
    g->setZero(H->Dimension());
    for (const Problem::Edge& e : p_.edges) {
      const EdgeResidual res = EvaluateEdge(*e.edge, poses[static_cast<std::size_t>(e.vi)],
                                            poses[static_cast<std::size_t>(e.vj)]);
      const MatB omega = e.edge->information.template topLeftCorner<B, B>();
      const Eigen::Matrix<double, B, 1> r = res.r.template head<B>();
      const double w =
          e.edge->robust ? optimizer_.KernelWeight(res.r.dot(e.edge->information * res.r)) : 1.0;
      const MatB Ji = res.J_i.template topLeftCorner<B, B>();
      const MatB Jj = res.J_j.template topLeftCorner<B, B>();
      const MatB JiT_W = w * Ji.transpose() * omega;
      const MatB JjT_W = w * Jj.transpose() * omega;
      const int bi = p_.block[static_cast<std::size_t>(e.vi)];
      const int bj = p_.block[static_cast<std::size_t>(e.vj)];
      if (bi >= 0) {
        AddBlock<B>(H, bi, bi, H->Slot(bi, bi), JiT_W * Ji);
        g->template segment<B>(bi * B) += JiT_W * r;
      }
      if (bj >= 0) {
        AddBlock<B>(H, bj, bj, H->Slot(bj, bj), JjT_W * Jj);
        g->template segment<B>(bj * B) += JjT_W * r;
      }
      if (bi >= 0 && bj >= 0) {
        if (bi < bj) {
          AddBlock<B>(H, bi, bj, e.slot, JiT_W * Jj);
        } else {
          AddBlock<B>(H, bj, bi, e.slot, JjT_W * Ji);
        }
      }
    }
  }

  /// poses * Exp(dx) per free vertex; false if a step leaves Sim(3) (scale overflow).
  bool Retract(const Eigen::VectorXd& dx, int block_size, std::vector<Sim3d>* out) const {
    *out = p_.poses;
    try {
      for (std::size_t v = 0; v < p_.poses.size(); ++v) {
        const int b = p_.block[v];
        if (b < 0) continue;
        Vector7d d = Vector7d::Zero();
        d.head(block_size) = dx.segment(b * block_size, block_size);
        (*out)[v] = p_.poses[v] * Sim3d::Exp(d);
      }
    } catch (const std::invalid_argument&) {
      return false;
    }
    return true;
  }

 private:
  const PoseGraphOptimizer& optimizer_;
  Problem& p_;
};

double StateNorm(const std::vector<Sim3d>& poses) {
  double n = 0.0;
  for (const Sim3d& S : poses) n += S.Translation().squaredNorm() + 1.0;
  return std::sqrt(n);
}

void CheckSe3Graph(const PoseGraph& graph) {
  for (const std::int64_t id : graph.VertexIds()) {
    CheckArgument(std::abs(graph.Pose(id).Scale() - 1.0) < 1e-12,
                  "PoseGraphOptimizer: SE(3) graph has a vertex with scale != 1");
  }
  for (const PoseGraphEdge& e : graph.Edges()) {
    CheckArgument(std::abs(e.S_i_j.Scale() - 1.0) < 1e-12,
                  "PoseGraphOptimizer: SE(3) graph has a measurement with scale != 1");
  }
}

}  // namespace

void PoseGraphOptimizerOptions::Check() const {
  CheckOption(kernel_width > 0.0, "PoseGraphOptimizerOptions", "kernel_width", "must be > 0");
  CheckOption(max_iterations >= 0, "PoseGraphOptimizerOptions", "max_iterations", "must be >= 0");
  CheckOption(function_tolerance >= 0.0 && gradient_tolerance >= 0.0 && parameter_tolerance >= 0.0,
              "PoseGraphOptimizerOptions", "*_tolerance", "must be >= 0");
  CheckOption(initial_lambda > 0.0, "PoseGraphOptimizerOptions", "initial_lambda", "must be > 0");
  CheckOption(min_diagonal > 0.0, "PoseGraphOptimizerOptions", "min_diagonal", "must be > 0");
}

PoseGraphOptimizer::PoseGraphOptimizer(const PoseGraphOptimizerOptions& options)
    : options_(options) {
  options_.Check();
}

double PoseGraphOptimizer::KernelWeight(double e) const {
  const double w2 = options_.kernel_width * options_.kernel_width;
  switch (options_.kernel) {
    case RobustKernel::kHuber:
      return e <= w2 ? 1.0 : options_.kernel_width / std::sqrt(e);
    case RobustKernel::kCauchy:
      return 1.0 / (1.0 + e / w2);
    case RobustKernel::kNone:
      break;
  }
  return 1.0;
}

double PoseGraphOptimizer::KernelCost(double e) const {
  const double w2 = options_.kernel_width * options_.kernel_width;
  switch (options_.kernel) {
    case RobustKernel::kHuber:
      return e <= w2 ? e : 2.0 * options_.kernel_width * std::sqrt(e) - w2;
    case RobustKernel::kCauchy:
      return w2 * std::log1p(e / w2);
    case RobustKernel::kNone:
      break;
  }
  return e;
}

PoseGraphSummary PoseGraphOptimizer::Optimize(PoseGraph* graph) const {
  CheckArgument(graph != nullptr, "PoseGraphOptimizer::Optimize: graph is null");
  if (!options_.optimize_scale) CheckSe3Graph(*graph);
  const auto start = Clock::now();
  const int B = options_.optimize_scale ? 7 : 6;
  Problem problem = Flatten(*graph);
  BlockSparseSymmetric H = MakePattern(&problem, B);
  Solver solver(*this, &problem);
  SymmetricSolver linear(options_.solver);
  PoseGraphSummary summary;
  double cost = solver.Cost(problem.poses);
  summary.initial_cost = cost;
  summary.termination = "iteration limit";
  if (problem.num_blocks == 0 || problem.edges.empty()) {
    summary.converged = true;
    summary.termination = "nothing to optimise";
  }
  double lambda = options_.initial_lambda;
  double nu = 2.0;
  bool rebuild = true;
  Eigen::VectorXd g;
  std::vector<Sim3d> candidate;
  while (!summary.converged && summary.iterations < options_.max_iterations) {
    const auto iteration_start = Clock::now();
    if (rebuild) {
      if (B == 7) {
        solver.Assemble<7>(problem.poses, &H, &g);
      } else {
        solver.Assemble<6>(problem.poses, &H, &g);
      }
      if (g.lpNorm<Eigen::Infinity>() <= options_.gradient_tolerance) {
        summary.converged = true;
        summary.termination = "gradient tolerance";
        break;
      }
    }
    const Eigen::VectorXd damping = H.DampDiagonal(lambda, options_.min_diagonal);
    ++summary.iterations;
    const bool factorized = linear.Factorize(H);
    Eigen::VectorXd dx;
    double new_cost = cost;
    double predicted = 0.0;
    bool retracted = false;
    if (factorized) {
      dx = linear.Solve(-g);
      if (dx.norm() <= options_.parameter_tolerance *
                           (StateNorm(problem.poses) + options_.parameter_tolerance)) {
        summary.converged = true;
        summary.termination = "parameter tolerance";
      } else if (dx.allFinite()) {
        // (H + D) dx = -g gives the model decrease -g.dx - dx.H.dx / 2 = (-g.dx + dx.D.dx) / 2.
        predicted = 0.5 * (-g.dot(dx) + dx.dot(damping.cwiseProduct(dx)));
        retracted = solver.Retract(dx, B, &candidate);
        if (retracted) new_cost = solver.Cost(candidate);
      }
    }
    H.AddToDiagonal(-damping);
    const double actual = cost - new_cost;
    if (retracted && std::isfinite(new_cost) && actual > 0.0 && predicted > 0.0) {
      const double rho = actual / predicted;
      lambda *= std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * rho - 1.0, 3));
      nu = 2.0;
      problem.poses.swap(candidate);
      ++summary.accepted_steps;
      rebuild = true;
      const double previous = cost;
      cost = new_cost;
      if (actual <= options_.function_tolerance * previous) {
        summary.converged = true;
        summary.termination = "function tolerance";
      }
    } else if (!summary.converged) {
      lambda *= nu;
      nu *= 2.0;
      rebuild = false;
      if (lambda > 1e32) {
        summary.converged = true;
        summary.termination = "no decrease (damping limit)";
      }
    }
    summary.iteration_ms.push_back(MillisecondsSince(iteration_start));
  }
  summary.final_cost = cost;
  for (std::size_t v = 0; v < problem.ids.size(); ++v) {
    graph->SetPose(problem.ids[v], problem.poses[v]);
  }
  summary.total_ms = MillisecondsSince(start);
  return summary;
}

}  // namespace parallax
