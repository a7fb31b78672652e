// Sim(3) pose graph: residual Jacobians, the LM optimiser with CHOLMOD, robust kernels.

#include "backend/pose_graph.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "../core/lie_test_utils.hpp"
#include "backend/block_sparse_cholesky.hpp"
#include "backend/pose_graph_optimizer.hpp"

namespace parallax {
namespace {

using test::NumericJacobian;
using test::RandomVector;

Sim3d RandomSim3(std::mt19937_64& rng, double range) {
  return Sim3d::Exp(RandomVector<7>(rng, range));
}

TEST(PoseGraphEdge, JacobiansMatchNumericDifferentiation) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 20; ++trial) {
    PoseGraphEdge edge;
    edge.S_i_j = RandomSim3(rng, 1.0);
    const Sim3d S_w_i = RandomSim3(rng, 2.0);
    // S_w_j near S_w_i * S_i_j, as in a graph being optimised, but not at the optimum.
    const Sim3d S_w_j = S_w_i * edge.S_i_j * Sim3d::Exp(RandomVector<7>(rng, 0.3));
    const EdgeResidual res = EvaluateEdge(edge, S_w_i, S_w_j);
    const auto f_i = [&](const Vector7d& d) {
      return EdgeError(edge.S_i_j, S_w_i * Sim3d::Exp(d), S_w_j);
    };
    const auto f_j = [&](const Vector7d& d) {
      return EdgeError(edge.S_i_j, S_w_i, S_w_j * Sim3d::Exp(d));
    };
    const Matrix7d Ji = NumericJacobian<7, 7>(f_i, Vector7d::Zero());
    const Matrix7d Jj = NumericJacobian<7, 7>(f_j, Vector7d::Zero());
    EXPECT_LT((res.J_i - Ji).cwiseAbs().maxCoeff(), 1e-6) << "trial " << trial;
    EXPECT_LT((res.J_j - Jj).cwiseAbs().maxCoeff(), 1e-6) << "trial " << trial;
    EXPECT_LT((res.r - f_i(Vector7d::Zero())).norm(), 1e-15);
  }
}

TEST(PoseGraphEdge, ResidualIsZeroAtTheMeasurementAndMatchesCeresForRigidEdges) {
  std::mt19937_64 rng(3);
  const Sim3d S_w_i = RandomSim3(rng, 1.0);
  PoseGraphEdge edge;
  edge.S_i_j = RandomSim3(rng, 1.0);
  EXPECT_LT(EdgeError(edge.S_i_j, S_w_i, S_w_i * edge.S_i_j).norm(), 1e-12);
  // Rigid: [R_m^T (R_i^T (t_j - t_i) - t_m); 2 vec(q_m^-1 q_i^-1 q_j)].
  const SE3d T_w_i = SE3d::Exp(RandomVector<6>(rng, 1.0));
  const SE3d T_w_j = SE3d::Exp(RandomVector<6>(rng, 1.0));
  const SE3d T_m = SE3d::Exp(RandomVector<6>(rng, 1.0));
  const Vector7d r = EdgeError(Sim3d(T_m), Sim3d(T_w_i), Sim3d(T_w_j));
  const Eigen::Vector3d t_expected =
      T_m.RotationMatrix().transpose() *
      (T_w_i.RotationMatrix().transpose() * (T_w_j.Translation() - T_w_i.Translation()) -
       T_m.Translation());
  Eigen::Quaterniond q = T_m.Rotation().UnitQuaternion().conjugate() *
                         T_w_i.Rotation().UnitQuaternion().conjugate() *
                         T_w_j.Rotation().UnitQuaternion();
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  EXPECT_LT((r.head<3>() - t_expected).norm(), 1e-12);
  EXPECT_LT((r.segment<3>(3) - 2.0 * q.vec()).norm(), 1e-12);
  EXPECT_NEAR(r[6], 0.0, 1e-15);
}

/// Ground truth of a loop: keyframes on a circle of radius 5, each with its own scale (a
/// monocular keyframe's normalised depth).
std::vector<Sim3d> CircleKeyframes(int n, std::mt19937_64& rng) {
  std::vector<Sim3d> poses;
  std::uniform_real_distribution<double> scale(0.7, 1.4);
  for (int k = 0; k < n; ++k) {
    const double a = 2.0 * M_PI * k / n;
    const SO3d R = SO3d::Exp(Eigen::Vector3d(0.0, a, 0.0));
    poses.emplace_back(
        k == 0 ? 1.0 : scale(rng), R,
        Eigen::Vector3d(5.0 * std::sin(a), 0.2 * std::sin(3 * a), 5.0 * std::cos(a)));
  }
  return poses;
}

double MaxPositionError(const PoseGraph& graph, const std::vector<Sim3d>& truth) {
  double worst = 0.0;
  for (std::size_t k = 0; k < truth.size(); ++k) {
    const auto id = static_cast<std::int64_t>(k);
    worst = std::max(worst, (graph.Pose(id).Translation() - truth[k].Translation()).norm());
  }
  return worst;
}

PoseGraphEdge Measured(std::int64_t i, std::int64_t j, const std::vector<Sim3d>& truth,
                       const Sim3d& error, double weight, EdgeKind kind) {
  PoseGraphEdge e;
  e.i = i;
  e.j = j;
  e.S_i_j =
      truth[static_cast<std::size_t>(i)].Inverse() * truth[static_cast<std::size_t>(j)] * error;
  e.information = weight * Matrix7d::Identity();
  e.kind = kind;
  return e;
}

/// A chain whose odometry measurements each carry 2% scale drift and small noise, closed by
/// three exact loop edges; vertices start at the chained (drifting) odometry.
PoseGraph DriftingLoop(const std::vector<Sim3d>& truth, std::mt19937_64& rng) {
  PoseGraph graph;
  const int n = static_cast<int>(truth.size());
  Sim3d chained = truth[0];
  graph.SetVertex(0, chained, true);
  for (int k = 1; k < n; ++k) {
    Vector7d noise = RandomVector<7>(rng, 0.002);
    noise[6] += 0.02;  // scale drift: each step over-estimates the scale by 2%
    const PoseGraphEdge e = Measured(k - 1, k, truth, Sim3d::Exp(noise), 1.0, EdgeKind::kOdometry);
    chained = chained * e.S_i_j;
    graph.SetVertex(k, chained);
    graph.AddEdge(e);
  }
  for (int back = 1; back <= 3; ++back) {
    graph.AddEdge(Measured(n - back, 0, truth, Sim3d(), 100.0, EdgeKind::kLoop));
  }
  return graph;
}

TEST(PoseGraphOptimizer, LoopEdgesRemoveScaleDriftFromAChain) {
  std::mt19937_64 rng(11);
  const std::vector<Sim3d> truth = CircleKeyframes(40, rng);
  PoseGraph graph = DriftingLoop(truth, rng);
  const double before = MaxPositionError(graph, truth);
  const double last_scale_before = graph.Pose(39).Scale() / truth[39].Scale();
  const PoseGraphSummary s = PoseGraphOptimizer().Optimize(&graph);
  EXPECT_TRUE(s.converged) << s.termination;
  EXPECT_LT(s.final_cost, 1e-3 * s.initial_cost);
  const double after = MaxPositionError(graph, truth);
  EXPECT_GT(before, 5.0);  // the drift is real: metres of error before
  EXPECT_LT(after, 0.05 * before) << "before " << before << " after " << after;
  EXPECT_GT(last_scale_before, 1.5);
  EXPECT_NEAR(graph.Pose(39).Scale() / truth[39].Scale(), 1.0, 0.03);
}

TEST(PoseGraphOptimizer, EdgesMarkedNotRobustAreExemptFromTheKernel) {
  // Two vertices, a loop edge 10 sigmas off: under Huber (width 2) its cost is linear beyond
  // the width; marked not robust (as verified loops are) it is the plain quadratic.
  const auto cost = [](bool robust) {
    PoseGraph graph;
    graph.SetVertex(0, Sim3d(), true);
    graph.SetVertex(1, Sim3d(1.0, SO3d(), Eigen::Vector3d(1.0, 0.0, 0.0)));
    PoseGraphEdge e;
    e.i = 0;
    e.j = 1;
    e.S_i_j = Sim3d(1.0, SO3d(), Eigen::Vector3d(1.1, 0.0, 0.0));
    e.information = 1e4 * Matrix7d::Identity();  // sigma 0.01: the residual is 10 sigmas
    e.kind = EdgeKind::kLoop;
    e.robust = robust;
    graph.AddEdge(e);
    PoseGraphOptimizerOptions huber;
    huber.kernel = RobustKernel::kHuber;
    huber.kernel_width = 2.0;
    huber.max_iterations = 1;
    const PoseGraphSummary s = PoseGraphOptimizer(huber).Optimize(&graph);
    return s.initial_cost;
  };
  EXPECT_NEAR(cost(false), 0.5 * 100.0, 1e-6);
  EXPECT_NEAR(cost(true), 0.5 * (2.0 * 2.0 * 10.0 - 4.0), 1e-6);  // Huber: 2 w e - w^2
}

TEST(PoseGraphOptimizer, RobustKernelDownWeightsOneWrongEdgeAmongTwenty) {
  std::mt19937_64 rng(5);
  const std::vector<Sim3d> truth = CircleKeyframes(10, rng);
  const auto build = [&](std::mt19937_64& noise_rng) {
    PoseGraph graph;
    for (int k = 0; k < 10; ++k) graph.SetVertex(k, truth[static_cast<std::size_t>(k)], k == 0);
    for (int k = 1; k < 10; ++k) {
      graph.AddEdge(Measured(k - 1, k, truth, Sim3d::Exp(RandomVector<7>(noise_rng, 0.01)), 1.0,
                             EdgeKind::kOdometry));
    }
    for (int k = 2; k < 10; ++k) {
      graph.AddEdge(Measured(k - 2, k, truth, Sim3d::Exp(RandomVector<7>(noise_rng, 0.01)), 1.0,
                             EdgeKind::kNeighbour));
    }
    graph.AddEdge(Measured(9, 0, truth, Sim3d(), 1.0, EdgeKind::kLoop));
    graph.AddEdge(Measured(8, 0, truth, Sim3d(), 1.0, EdgeKind::kLoop));
    // The twentieth: a false loop, 40 degrees and 2 units off.
    Vector7d wrong = Vector7d::Zero();
    wrong << 2.0, 0.0, 0.0, 0.0, 0.7, 0.0, 0.3;
    graph.AddEdge(Measured(5, 0, truth, Sim3d::Exp(wrong), 1.0, EdgeKind::kLoop));
    return graph;
  };
  std::mt19937_64 rng_a(9), rng_b(9);
  PoseGraph plain = build(rng_a);
  PoseGraph robust = build(rng_b);
  ASSERT_EQ(plain.Edges().size(), 20u);
  PoseGraphOptimizer().Optimize(&plain);
  PoseGraphOptimizerOptions options;
  options.kernel = RobustKernel::kCauchy;
  options.kernel_width = 0.1;
  const PoseGraphOptimizer robust_optimizer(options);
  robust_optimizer.Optimize(&robust);
  const double plain_error = MaxPositionError(plain, truth);
  const double robust_error = MaxPositionError(robust, truth);
  EXPECT_GT(plain_error, 0.3);
  EXPECT_LT(robust_error, 0.1 * plain_error) << plain_error << " vs " << robust_error;
  const PoseGraphEdge& wrong = robust.Edges().back();
  const Vector7d r = EdgeError(wrong.S_i_j, robust.Pose(wrong.i), robust.Pose(wrong.j));
  EXPECT_LT(robust_optimizer.KernelWeight(r.dot(wrong.information * r)), 0.01);
}

TEST(PoseGraphOptimizer, CholmodAndDenseSolvesAgree) {
  std::mt19937_64 rng(21);
  const std::vector<Sim3d> truth = CircleKeyframes(25, rng);
  PoseGraph a = DriftingLoop(truth, rng);
  PoseGraph b = a;
  PoseGraphOptimizerOptions options;
  options.max_iterations = 8;  // compare the iterates, not just the optimum
  options.function_tolerance = 0.0;
  PoseGraphOptimizer(options).Optimize(&a);
  options.solver = LinearSolverKind::kDense;
  PoseGraphOptimizer(options).Optimize(&b);
  for (const std::int64_t id : a.VertexIds()) {
    EXPECT_LT((a.Pose(id).Log() - b.Pose(id).Log()).norm(), 1e-8) << "vertex " << id;
  }
  EXPECT_NEAR(a.Cost(), b.Cost(), 1e-9 * (1.0 + a.Cost()));
}

TEST(PoseGraphOptimizer, Se3ModeKeepsScaleAndRejectsSimilarities) {
  std::mt19937_64 rng(2);
  PoseGraph graph;
  graph.SetVertex(0, Sim3d(), true);
  graph.SetVertex(1, Sim3d(SE3d::Exp(RandomVector<6>(rng, 0.5))));
  PoseGraphEdge e;
  e.i = 0;
  e.j = 1;
  e.S_i_j = Sim3d(SE3d::Exp(RandomVector<6>(rng, 0.5)));
  graph.AddEdge(e);
  PoseGraphOptimizerOptions options;
  options.optimize_scale = false;
  PoseGraphOptimizer(options).Optimize(&graph);
  EXPECT_LT((graph.Pose(1).Log() - e.S_i_j.Log()).norm(), 1e-9);
  EXPECT_EQ(graph.Pose(1).Scale(), 1.0);
  graph.SetPose(1, Sim3d(2.0, SO3d(), Eigen::Vector3d::Zero()));
  EXPECT_THROW(PoseGraphOptimizer(options).Optimize(&graph), std::invalid_argument);
}

TEST(PoseGraph, RejectsBadEdges) {
  PoseGraph graph;
  graph.SetVertex(0, Sim3d());
  graph.SetVertex(1, Sim3d());
  PoseGraphEdge e;
  e.i = 0;
  e.j = 2;
  EXPECT_THROW(graph.AddEdge(e), std::invalid_argument);
  e.j = 0;
  EXPECT_THROW(graph.AddEdge(e), std::invalid_argument);
  e.j = 1;
  e.information(0, 0) = -1.0;
  EXPECT_THROW(graph.AddEdge(e), std::invalid_argument);
  e.information = Matrix7d::Identity();
  e.information(0, 1) = 0.5;
  EXPECT_THROW(graph.AddEdge(e), std::invalid_argument);  // not symmetric
}

TEST(BlockSparseSymmetric, PatternProductAndDenseAgree) {
  BlockSparseSymmetric A(4, 2, {{0, 2}, {3, 1}, {2, 0}});
  EXPECT_EQ(A.Slot(0, 2), 0);
  EXPECT_EQ(A.Slot(2, 2), 1);
  EXPECT_EQ(A.Slot(1, 2), -1);
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int c = 0; c < 4; ++c) {
    for (int r = 0; r <= c; ++r) {
      const int slot = A.Slot(r, c);
      if (slot < 0) continue;
      for (int k = 0; k < 2; ++k) {
        for (int i = 0; i < 2; ++i) {
          if (r < c || i <= k) A.Entry(c, slot, i, k) = u(rng) + (r == c && i == k ? 4.0 : 0.0);
        }
      }
    }
  }
  const Eigen::MatrixXd D = A.ToDense();
  EXPECT_LT((D - D.transpose()).norm(), 1e-15);
  EXPECT_EQ(D(1, 4), A.Entry(2, 0, 1, 0));  // block (0, 2), entry (1, 0)
  EXPECT_EQ(D(4, 1), D(1, 4));
  EXPECT_EQ(D(0, 2), 0.0);  // block (0, 1) is not in the pattern
  const Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(8, -1.0, 2.0);
  EXPECT_LT((A.Multiply(x) - D * x).norm(), 1e-12);
  SymmetricSolver cholmod(LinearSolverKind::kCholmod);
  SymmetricSolver dense(LinearSolverKind::kDense);
  ASSERT_TRUE(cholmod.Factorize(A));
  ASSERT_TRUE(dense.Factorize(A));
  EXPECT_LT((cholmod.Solve(x) - dense.Solve(x)).norm(), 1e-10);
  EXPECT_LT((D * cholmod.Solve(x) - x).norm(), 1e-10);
}

TEST(SymmetricSolver, ReportsAnIndefiniteMatrix) {
  BlockSparseSymmetric A(2, 1, {{0, 1}});
  A.Entry(0, 0, 0, 0) = 1.0;
  A.Entry(1, 0, 0, 0) = 2.0;  // [[1, 2], [2, 1]]: eigenvalues 3 and -1
  A.Entry(1, 1, 0, 0) = 1.0;
  SymmetricSolver cholmod(LinearSolverKind::kCholmod);
  EXPECT_FALSE(cholmod.Factorize(A));
  SymmetricSolver dense(LinearSolverKind::kDense);
  EXPECT_FALSE(dense.Factorize(A));
}

}  // namespace
}  // namespace parallax
