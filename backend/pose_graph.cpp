#include "backend/pose_graph.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>

#include "core/check.hpp"

namespace parallax {
namespace {

struct ErrorParts {
  double scale;
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  Eigen::Quaterniond q;  ///< canonical: w >= 0
};

ErrorParts ErrorTransform(const Sim3d& S_i_j, const Sim3d& S_w_i, const Sim3d& S_w_j) {
  const Sim3d E = S_i_j.Inverse() * S_w_i.Inverse() * S_w_j;
  Eigen::Quaterniond q = E.Rotation().UnitQuaternion();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  return {E.Scale(), E.Rotation().Matrix(), E.Translation(), q};
}

Vector7d Residual(const ErrorParts& e) {
  Vector7d r;
  r << e.t, 2.0 * e.q.vec(), std::log(e.scale);
  return r;
}

}  // namespace

Vector7d EdgeError(const Sim3d& S_i_j, const Sim3d& S_w_i, const Sim3d& S_w_j) {
  return Residual(ErrorTransform(S_i_j, S_w_i, S_w_j));
}

EdgeResidual EvaluateEdge(const PoseGraphEdge& edge, const Sim3d& S_w_i, const Sim3d& S_w_j) {
  const ErrorParts e = ErrorTransform(edge.S_i_j, S_w_i, S_w_j);
  EdgeResidual out;
  out.r = Residual(e);
  const Eigen::Vector3d v = e.q.vec();
  const double w = e.q.w();
  // d r / d(right perturbation of E): E Exp(d) = (s e^sigma, R Exp(omega), s R upsilon + t).
  Matrix7d J_right = Matrix7d::Zero();
  J_right.block<3, 3>(0, 0) = e.scale * e.R;
  J_right.block<3, 3>(3, 3) = w * Eigen::Matrix3d::Identity() + SO3d::Hat(v);
  J_right(6, 6) = 1.0;
  // d r / d(left perturbation of E): Exp(d) E = (e^sigma s, Exp(omega) R, t + upsilon +
  // omega x t + sigma t).
  Matrix7d J_left = Matrix7d::Zero();
  J_left.block<3, 3>(0, 0).setIdentity();
  J_left.block<3, 3>(0, 3) = -SO3d::Hat(e.t);
  J_left.block<3, 1>(0, 6) = e.t;
  J_left.block<3, 3>(3, 3) = w * Eigen::Matrix3d::Identity() - SO3d::Hat(v);
  J_left(6, 6) = 1.0;
  // S_w_j Exp(d_j) gives E Exp(d_j); S_w_i Exp(d_i) gives Exp(-Adj(S_i_j^-1) d_i) E.
  out.J_j = J_right;
  out.J_i = -J_left * edge.S_i_j.Inverse().Adjoint();
  return out;
}

void PoseGraph::SetVertex(std::int64_t id, const Sim3d& S_w_v, bool fixed) {
  vertices_[id] = Vertex{S_w_v, fixed};
}

void PoseGraph::SetFixed(std::int64_t id, bool fixed) { vertices_.at(id).fixed = fixed; }

void PoseGraph::AddEdge(const PoseGraphEdge& edge) {
  CheckArgument(HasVertex(edge.i) && HasVertex(edge.j),
                "PoseGraph::AddEdge: edge " + std::to_string(edge.i) + "-" +
                    std::to_string(edge.j) + " names a vertex that does not exist");
  CheckArgument(edge.i != edge.j, "PoseGraph::AddEdge: an edge needs two distinct vertices");
  CheckArgument(edge.information.allFinite(), "PoseGraph::AddEdge: information is not finite");
  CheckArgument((edge.information - edge.information.transpose()).cwiseAbs().maxCoeff() <=
                    1e-9 * (1.0 + edge.information.cwiseAbs().maxCoeff()),
                "PoseGraph::AddEdge: information is not symmetric");
  const Eigen::SelfAdjointEigenSolver<Matrix7d> eig(edge.information, Eigen::EigenvaluesOnly);
  CheckArgument(eig.eigenvalues().minCoeff() >= -1e-9 * (1.0 + eig.eigenvalues().maxCoeff()),
                "PoseGraph::AddEdge: information is not positive semi-definite");
  edges_.push_back(edge);
}

std::vector<std::int64_t> PoseGraph::VertexIds() const {
  std::vector<std::int64_t> ids;
  ids.reserve(vertices_.size());
  for (const auto& [id, vertex] : vertices_) ids.push_back(id);
  return ids;
}

double PoseGraph::Cost() const {
  double cost = 0.0;
  for (const PoseGraphEdge& edge : edges_) {
    const Vector7d r = EdgeError(edge.S_i_j, Pose(edge.i), Pose(edge.j));
    cost += 0.5 * r.dot(edge.information * r);
  }
  return cost;
}

}  // namespace parallax
