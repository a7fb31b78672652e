#pragma once
// The Levenberg-Marquardt loop shared by the SE(3) and Sim(3) trackers.

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>
#include <utility>
#include <vector>

namespace parallax {

/// A problem linearised at a state: cost and normal equations (already normalised and with
/// priors), and how many residuals it had.
template <int N>
struct LinearizedProblem {
  Eigen::Matrix<double, N, N> H = Eigen::Matrix<double, N, N>::Zero();
  Eigen::Matrix<double, N, 1> g = Eigen::Matrix<double, N, 1>::Zero();
  double cost = std::numeric_limits<double>::infinity();
  int residuals = 0;
};

struct LmSettings {
  int max_iterations = 10;
  /// Converged when an undamped step, or a rejected one, changes the cost by less than this
  /// fraction (the noise floor of the minimum).
  double relative_tolerance = 1e-3;
  /// Fewer residuals than this: the state is not trusted (stop).
  int min_residuals = 20;
  /// Only the first `active` parameters are solved for (others stay fixed); -1: all.
  int active = -1;
};

/// Iteration budget of `level` from a per-level list (missing entries use the last one).
inline int MaxIterationsForLevel(const std::vector<int>& per_level, int level) {
  return per_level[std::min(static_cast<std::size_t>(level), per_level.size() - 1)];
}

/// Minimises from *state. `linearize(state)` returns LinearizedProblem<N>; `retract(state,
/// delta)` applies a step. Steps solve (H + lambda diag(H)) delta = -g; lambda is 0 while
/// steps succeed, 0.2 after a failure and x4 per further failure (LSD-SLAM's schedule).
/// `linearize` may return a type derived from LinearizedProblem<N> that carries more of the
/// evaluation; `final_problem` (optional) receives the linearisation at the returned state,
/// so that a caller need not evaluate it again. Returns the number of iterations.
template <int N, typename State, typename Linearize, typename Retract,
          typename Problem = std::invoke_result_t<Linearize, const State&>>
int MinimizeLevenbergMarquardt(State* state, const Linearize& linearize, const Retract& retract,
                               const LmSettings& settings, Problem* final_problem = nullptr) {
  static_assert(std::is_base_of_v<LinearizedProblem<N>, Problem>,
                "linearize must return a LinearizedProblem<N>");
  const int active = settings.active < 0 ? N : settings.active;
  Problem current = linearize(*state);
  double lambda = 0.0;
  int iterations = 0;
  while (iterations < settings.max_iterations && current.residuals >= settings.min_residuals) {
    ++iterations;
    Eigen::MatrixXd A = current.H.topLeftCorner(active, active);
    A.diagonal() *= 1.0 + lambda;
    Eigen::Matrix<double, N, 1> delta = Eigen::Matrix<double, N, 1>::Zero();
    delta.head(active) = A.ldlt().solve(-current.g.head(active));
    if (!delta.allFinite()) break;
    const State candidate = retract(*state, delta);
    Problem next = linearize(candidate);
    const bool valid = next.residuals >= settings.min_residuals && std::isfinite(next.cost);
    const double change = valid ? (next.cost - current.cost) / current.cost : 1.0;
    if (valid && next.cost < current.cost) {
      const bool converged = lambda == 0.0 && -change < settings.relative_tolerance;
      *state = candidate;
      current = std::move(next);
      lambda = lambda <= 0.2 ? 0.0 : 0.5 * lambda;
      if (converged) break;
    } else {
      if ((valid && change < settings.relative_tolerance) || delta.squaredNorm() < 1e-12) break;
      lambda = lambda == 0.0 ? 0.2 : 4.0 * lambda;
    }
  }
  if (final_problem != nullptr) *final_problem = std::move(current);
  return iterations;
}

}  // namespace parallax
