#pragma once
// The backend stage: constraint search for finished keyframes (direct Sim(3) alignment with
// the reciprocal check) and pose-graph optimisation of the keyframe graph
// (docs/architecture.md, "Backend").

#include <cstdint>
#include <exception>
#include <optional>
#include <utility>
#include <vector>

#include "backend/keyframe_graph.hpp"
#include "backend/pose_graph_optimizer.hpp"
#include "tracking/sim3_tracker.hpp"

namespace parallax {

struct GraphBackendOptions {
  Sim3TrackerOptions alignment;
  /// Neighbour candidates: keyframes (other than the parent) whose centre is within this
  /// distance of the finished keyframe's, relative to its mean depth, and whose optical axes
  /// differ by less than `neighbour_max_angle_deg`; the nearest `max_neighbours` are aligned.
  double neighbour_max_distance = 1.0;
  double neighbour_max_angle_deg = 30.0;
  int max_neighbours = 2;
  /// An alignment is an edge only if both directions converge ("ok") and their reciprocal
  /// Mahalanobis distance, with the scaled information below, is under this (chi^2 with 7
  /// degrees of freedom: 24.3 is its 99.9% quantile).
  double max_reciprocal_mahalanobis = 24.3;
  /// Scale of the alignment's information matrix in the graph: direct alignment's Hessian
  /// treats pixels as independent and is overconfident. Chosen on the KITTI and TUM clips
  /// (the tuning set) so that the median reciprocal distance of parent alignments, ~1,500
  /// unscaled, becomes chi^2(7)'s median 6.35 (docs/math/pose_graph.md).
  double information_scale = 4e-3;
  /// Information of an odometry edge whose alignment fails (the tracking chain's
  /// measurement is kept so the graph stays connected): the accepted odometry edge of median
  /// trace so far, or, before any was accepted, this diagonal (per residual unit^2). A fixed
  /// weak value made such an edge absorb a whole loop correction (a 5 cm step on the orbit,
  /// its weight being 1e-4 of its neighbours').
  double fallback_odometry_information = 1e4;
  bool fallback_from_median = true;
  /// true: an odometry edge measures what the keyframe alignment found; false: the tracking
  /// chain's S_parent_kf, weighted by the alignment's information.
  bool odometry_from_alignment = true;
  PoseGraphOptimizerOptions optimizer{
      .kernel = RobustKernel::kHuber, .kernel_width = 2.0, .max_iterations = 20};

  void Check() const;
};

/// What the backend did for one finished keyframe.
struct BackendReport {
  int alignments = 0;  ///< Sim(3) alignments run (each direction counts)
  int edges_added = 0;
  int edges_rejected = 0;  ///< candidates that failed convergence or the reciprocal check
  std::optional<PoseGraphSummary> optimisation;  ///< empty when nothing was optimised
};

/// How compacted keyframes are rebuilt for alignment (see Materialize).
struct KeyframeBuildOptions {
  PinholeCamera camera;
  PyramidOptions pyramid;
  TrackingReferenceOptions reference;
};

class GraphBackend {
 public:
  GraphBackend(const GraphBackendOptions& options, const KeyframeBuildOptions& build);

  /// Keyframe `id` was finished (it is in the graph): the odometry edge to `parent` with the
  /// tracking chain's measurement S_parent_kf (refined and weighted by alignment), edges to
  /// nearby keyframes, and a warm-started optimisation of the graph.
  BackendReport KeyframeFinished(KeyframeGraph* graph, std::int64_t id,
                                 std::optional<std::int64_t> parent, const Sim3d& S_parent_kf);

  const GraphBackendOptions& Options() const { return options_; }
  /// The information of an odometry edge whose alignment failed (see the options); also
  /// the weight of the unfinished keyframe's edge in a saved map.
  Matrix7d FallbackInformation() const;

  /// A direct Sim(3) alignment of two keyframes, checked both ways.
  struct Alignment {
    bool converged = false;  ///< both directions converged (the fields below are set)
    bool accepted = false;   ///< ... and passed the reciprocal check
    Sim3d S_a_b;             ///< a aligned to b
    Sim3d S_a_b_reverse;     ///< b aligned to a, inverted
    Matrix7d information = Matrix7d::Zero();  ///< in pose-graph residual coordinates
    double reciprocal_distance = 0.0;         ///< with the scaled information
  };
  /// Aligns keyframes a and b both ways from the guess S_a_b (compacted keyframes are
  /// rebuilt for it): two Sim(3) alignments. Accepted when both directions converge "ok" (or
  /// "poor" too, with `accept_poor`) and pass the reciprocal check; a converged pair that
  /// fails the check is returned with accepted = false. Thread-safe (const, no shared state).
  Alignment Align(const KeyframeGraph& graph, std::int64_t a, std::int64_t b,
                  const Sim3d& S_a_b_guess, bool accept_poor = false) const;

 private:
  /// Keyframe `b` aligned with each (a, guess S_a_b) in `with`, concurrently (TBB); each
  /// alignment runs alone, so the results are those of aligning in turn, bit for bit. An
  /// alignment that threw holds its exception.
  struct AlignmentOutcome {
    Alignment alignment;
    std::exception_ptr error;
  };
  std::vector<AlignmentOutcome> AlignAll(
      const KeyframeGraph& graph, std::int64_t b,
      const std::vector<std::pair<std::int64_t, Sim3d>>& with) const;

  std::vector<std::int64_t> NeighbourCandidates(const KeyframeGraph& graph, std::int64_t id,
                                                std::optional<std::int64_t> parent) const;

  GraphBackendOptions options_;
  KeyframeBuildOptions build_;
  /// Traces and information matrices of the accepted odometry edges (for the fallback).
  std::vector<std::pair<double, Matrix7d>> accepted_odometry_;
  Sim3Tracker aligner_;
  PoseGraphOptimizer optimizer_;
};

}  // namespace parallax
