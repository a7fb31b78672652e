#pragma once
// A Sim(3) pose graph: vertices are keyframe-to-world similarities S_w_i, edges relative
// measurements S_i_j with information matrices. Residual and Jacobians: docs/math/pose_graph.md.

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <vector>

#include "core/sim3.hpp"

namespace parallax {

/// Where an edge came from (stats and the map file keep them apart).
enum class EdgeKind {
  kOdometry,   ///< consecutive keyframes (the tracker's chain)
  kNeighbour,  ///< constraint search among nearby keyframes
  kLoop,       ///< place recognition
};

/// Order: translation (3), rotation (3), log-scale (1), as the Sim3 tangent.
using Matrix7d = Eigen::Matrix<double, 7, 7>;
using Vector7d = Eigen::Matrix<double, 7, 1>;

/// A relative measurement S_i_j (maps points of vertex j into vertex i, i.e. the expected
/// value of S_w_i^-1 * S_w_j), with its information matrix in residual coordinates.
struct PoseGraphEdge {
  std::int64_t i = 0;
  std::int64_t j = 0;
  Sim3d S_i_j;
  Matrix7d information = Matrix7d::Identity();
  EdgeKind kind = EdgeKind::kOdometry;
  /// The optimiser's robust kernel applies to this edge (false: always quadratic). Loop
  /// edges stay robust: exempting them made the orbits' ATE worse (docs/place_recognition.md).
  bool robust = true;
};

/// The residual of one edge and its Jacobians with respect to right perturbations of the
/// two vertices (S_w_i <- S_w_i * Exp(d_i)). r = [t_E; 2 vec(q_E); log s_E] with
/// E = S_i_j^-1 S_w_i^-1 S_w_j (q_E with w >= 0): for s = 1 the rotation and translation rows
/// are Ceres' pose_graph_3d residual exactly.
struct EdgeResidual {
  Vector7d r;
  Matrix7d J_i;
  Matrix7d J_j;
};

/// Evaluates the residual (and Jacobians) of `edge` at the given vertex poses.
EdgeResidual EvaluateEdge(const PoseGraphEdge& edge, const Sim3d& S_w_i, const Sim3d& S_w_j);

/// The residual alone (no Jacobians).
Vector7d EdgeError(const Sim3d& S_i_j, const Sim3d& S_w_i, const Sim3d& S_w_j);

/// A pose graph: vertices by id (std::map, so iteration order and therefore every result are
/// deterministic) and edges in insertion order.
class PoseGraph {
 public:
  /// Adds or replaces a vertex. `fixed` vertices are not optimised (the gauge).
  void SetVertex(std::int64_t id, const Sim3d& S_w_v, bool fixed = false);
  /// Throws std::invalid_argument if an end is not a vertex, i == j, or the information
  /// matrix is not symmetric positive semi-definite with finite entries.
  void AddEdge(const PoseGraphEdge& edge);
  void SetFixed(std::int64_t id, bool fixed);

  bool HasVertex(std::int64_t id) const { return vertices_.count(id) > 0; }
  /// Throws std::out_of_range for an unknown id.
  const Sim3d& Pose(std::int64_t id) const { return vertices_.at(id).S_w_v; }
  void SetPose(std::int64_t id, const Sim3d& S_w_v) { vertices_.at(id).S_w_v = S_w_v; }
  bool IsFixed(std::int64_t id) const { return vertices_.at(id).fixed; }
  std::size_t NumVertices() const { return vertices_.size(); }
  const std::vector<PoseGraphEdge>& Edges() const { return edges_; }
  /// Vertex ids in ascending order.
  std::vector<std::int64_t> VertexIds() const;

  /// 0.5 * sum r^T Omega r over all edges (no robust kernel).
  double Cost() const;

 private:
  struct Vertex {
    Sim3d S_w_v;
    bool fixed = false;
  };
  std::map<std::int64_t, Vertex> vertices_;
  std::vector<PoseGraphEdge> edges_;
};

}  // namespace parallax
