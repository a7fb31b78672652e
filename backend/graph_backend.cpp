#include "backend/graph_backend.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "core/angles.hpp"
#include "core/check.hpp"

namespace parallax {

void GraphBackendOptions::Check() const {
  alignment.Check();
  optimizer.Check();
  CheckOption(neighbour_max_distance >= 0.0, "GraphBackendOptions", "neighbour_max_distance",
              "must be >= 0");
  CheckOption(neighbour_max_angle_deg >= 0.0, "GraphBackendOptions", "neighbour_max_angle_deg",
              "must be >= 0");
  CheckOption(max_neighbours >= 0, "GraphBackendOptions", "max_neighbours", "must be >= 0");
  CheckOption(max_reciprocal_mahalanobis > 0.0, "GraphBackendOptions", "max_reciprocal_mahalanobis",
              "must be > 0");
  CheckOption(information_scale > 0.0, "GraphBackendOptions", "information_scale", "must be > 0");
  CheckOption(fallback_odometry_information > 0.0, "GraphBackendOptions",
              "fallback_odometry_information", "must be > 0");
}

GraphBackend::GraphBackend(const GraphBackendOptions& options, const KeyframeBuildOptions& build)
    : options_(options), build_(build), aligner_(options.alignment), optimizer_(options.optimizer) {
  options_.Check();
}

GraphBackend::Alignment GraphBackend::Align(const KeyframeGraph& graph, std::int64_t a_id,
                                            std::int64_t b_id, const Sim3d& S_a_b_guess,
                                            bool accept_poor) const {
  Alignment out;
  const auto a_ptr =
      Materialize(graph.GetPtr(a_id), build_.camera, build_.pyramid, build_.reference);
  const auto b_ptr =
      Materialize(graph.GetPtr(b_id), build_.camera, build_.pyramid, build_.reference);
  const Keyframe& a = *a_ptr;
  const Keyframe& b = *b_ptr;
  const auto usable = [&](TrackingStatus status) {
    return status == TrackingStatus::kOk || (accept_poor && status == TrackingStatus::kPoor);
  };
  const Sim3TrackingResult a_b = aligner_.Track(*a.reference, *b.reference, S_a_b_guess);
  if (!usable(a_b.status)) return out;
  const Sim3TrackingResult b_a =
      aligner_.Track(*b.reference, *a.reference, a_b.S_ref_other.Inverse());
  if (!usable(b_a.status)) return out;
  out.converged = true;
  out.S_a_b = a_b.S_ref_other;
  out.S_a_b_reverse = b_a.S_ref_other.Inverse();
  // The distance with the graph's (scaled) information: scaling the information by s
  // scales the distance by s.
  out.reciprocal_distance = options_.information_scale * ReciprocalMahalanobis(a_b, b_a);
  // The tracker's information is for S' = Exp(eps) S_a_b; the graph residual of the edge is
  // r = Adj(S_a_b^-1) eps to first order, so Omega_r = Adj(S)^T Omega_eps Adj(S).
  const Matrix7d adjoint = out.S_a_b.Adjoint();
  out.information = options_.information_scale * adjoint.transpose() * a_b.information * adjoint;
  out.information = 0.5 * (out.information + out.information.transpose()).eval();
  out.accepted = out.reciprocal_distance < options_.max_reciprocal_mahalanobis;
  return out;
}

std::vector<std::int64_t> GraphBackend::NeighbourCandidates(
    const KeyframeGraph& graph, std::int64_t id, std::optional<std::int64_t> parent) const {
  const Sim3d& S_w_kf = graph.Pose(id);
  const Eigen::Vector3d axis = S_w_kf.Rotation() * Eigen::Vector3d::UnitZ();
  std::vector<std::pair<double, std::int64_t>> near;
  for (const std::int64_t other : graph.Ids()) {
    // Poses of another map are in another world frame: no distance to compare.
    if (other == id || other == parent || graph.HasEdge(id, other) ||
        graph.MapOf(other) != graph.MapOf(id)) {
      continue;
    }
    const Sim3d& S_w_other = graph.Pose(other);
    // Distance in units of the finished keyframe's mean depth (its scale in the world).
    const double distance =
        (S_w_other.Translation() - S_w_kf.Translation()).norm() / S_w_kf.Scale();
    const double angle = AngleBetweenDeg(axis, S_w_other.Rotation() * Eigen::Vector3d::UnitZ());
    if (distance <= options_.neighbour_max_distance && angle <= options_.neighbour_max_angle_deg) {
      near.emplace_back(distance, other);
    }
  }
  std::sort(near.begin(), near.end());
  std::vector<std::int64_t> ids;
  for (std::size_t k = 0; k < near.size() && static_cast<int>(k) < options_.max_neighbours; ++k) {
    ids.push_back(near[k].second);
  }
  return ids;
}

Matrix7d GraphBackend::FallbackInformation() const {
  if (!options_.fallback_from_median || accepted_odometry_.empty()) {
    return options_.fallback_odometry_information * Matrix7d::Identity();
  }
  std::vector<std::pair<double, std::size_t>> order;
  order.reserve(accepted_odometry_.size());
  for (std::size_t k = 0; k < accepted_odometry_.size(); ++k) {
    order.emplace_back(accepted_odometry_[k].first, k);
  }
  const auto middle = order.begin() + static_cast<std::ptrdiff_t>(order.size() / 2);
  std::nth_element(order.begin(), middle, order.end());
  return accepted_odometry_[middle->second].second;
}

std::vector<GraphBackend::AlignmentOutcome> GraphBackend::AlignAll(
    const KeyframeGraph& graph, std::int64_t b,
    const std::vector<std::pair<std::int64_t, Sim3d>>& with) const {
  std::vector<AlignmentOutcome> outcomes(with.size());
  tbb::parallel_for(std::size_t{0}, with.size(), [&](std::size_t k) {
    try {
      outcomes[k].alignment = Align(graph, with[k].first, b, with[k].second);
    } catch (...) {
      outcomes[k].error = std::current_exception();
    }
  });
  return outcomes;
}

BackendReport GraphBackend::KeyframeFinished(KeyframeGraph* graph, std::int64_t id,
                                             std::optional<std::int64_t> parent,
                                             const Sim3d& S_parent_kf) {
  BackendReport report;
  // The parent's and the neighbours' alignments are independent (the graph's poses do not
  // change until the optimisation below): they run together, and their edges are added in
  // the order aligning one after the other would add them, up to the first that threw.
  const bool align_parent = parent && graph->Contains(*parent) && !graph->HasEdge(*parent, id);
  std::vector<std::pair<std::int64_t, Sim3d>> with;
  if (align_parent) with.emplace_back(*parent, S_parent_kf);
  for (const std::int64_t other : NeighbourCandidates(*graph, id, parent)) {
    with.emplace_back(other, graph->Pose(other).Inverse() * graph->Pose(id));
  }
  const std::vector<AlignmentOutcome> outcomes = AlignAll(*graph, id, with);
  for (std::size_t k = 0; k < outcomes.size(); ++k) {
    report.alignments += 2;
    if (outcomes[k].error) std::rethrow_exception(outcomes[k].error);
    const Alignment& a = outcomes[k].alignment;
    if (align_parent && k == 0) {
      // The chain's measurement is what tracking used; the alignment, when it agrees, says
      // how well it is known. A failed alignment keeps the chain with a fixed weight.
      PoseGraphEdge edge;
      edge.i = *parent;
      edge.j = id;
      edge.kind = EdgeKind::kOdometry;
      edge.S_i_j = a.accepted && options_.odometry_from_alignment ? a.S_a_b : S_parent_kf;
      edge.information = a.accepted ? a.information : FallbackInformation();
      if (a.accepted) accepted_odometry_.emplace_back(a.information.trace(), a.information);
      graph->AddEdge(edge);
      ++report.edges_added;
      report.edges_rejected += a.accepted ? 0 : 1;
      continue;
    }
    if (!a.accepted) {
      ++report.edges_rejected;
      continue;
    }
    graph->AddEdge(PoseGraphEdge{with[k].first, id, a.S_a_b, a.information, EdgeKind::kNeighbour});
    ++report.edges_added;
  }
  if (report.edges_added > 0 && graph->Size() >= 2) {
    report.optimisation = optimizer_.Optimize(&graph->Poses());
  }
  return report;
}

}  // namespace parallax
