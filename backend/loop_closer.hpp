#pragma once
// Loop closure: place-recognition candidates for a finished keyframe, kept when consistent
// over consecutive keyframes, verified by ORB matches lifted with the keyframes' semi-dense
// depth (Sim(3) RANSAC) and by direct Sim(3) alignment with the reciprocal check; an
// accepted loop becomes a pose-graph edge and the graph is optimised
// (docs/place_recognition.md, "Loop closure").

#include <cstdint>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "backend/graph_backend.hpp"
#include "backend/keyframe_graph.hpp"
#include "backend/place_recognizer.hpp"
#include "backend/sim3_ransac.hpp"

namespace parallax {

struct LoopClosureOptions {
  bool enabled = true;
  PlaceRecognitionOptions place;
  /// Never a loop with the keyframes connected to the new one by an edge, nor with the last
  /// `exclude_recent_keyframes` keyframes before it (the current neighbourhood).
  int exclude_recent_keyframes = 10;
  /// A candidate scores at least this (L1) and at least the lowest score between the new
  /// keyframe and its connected keyframes (ORB-SLAM's relative gate).
  double min_score = 0.01;
  int max_candidates = 3;
  /// Consecutive keyframes (the new one included) whose candidates must share a keyframe
  /// (candidate or one connected to it) before any is verified.
  int consistency = 2;
  /// ORB matches with depth needed before RANSAC.
  int min_matches = 30;
  /// Depth used for a keypoint only when its relative standard deviation (sqrt(var)/idepth)
  /// is below this.
  double max_relative_depth_std = 0.2;
  Sim3RansacOptions ransac;
  /// The direct alignment of a loop may converge "poor" (fewer consistent points: the two
  /// visits see the place from further apart than neighbours do) and still be accepted,
  /// the reciprocal check deciding; RANSAC has already found the geometry.
  bool accept_poor_alignment = true;
  /// The two directions of the loop's direct alignment must agree within these bounds (the
  /// translation in units of the keyframe's mean depth). Wide-baseline revisits make the
  /// alignment's Hessian-based distance meaningless (hundreds of "sigmas" for a 2 mm
  /// disagreement), so the loop's reciprocal check is geometric.
  double max_reciprocal_translation = 0.05;
  double max_reciprocal_rotation_deg = 2.0;
  double max_reciprocal_log_scale = 0.05;
  /// Drift bound (within one map; a loop between two maps merges them instead): the loop
  /// may move the new keyframe (relative to the candidate) by at most
  /// this share of the path travelled between them. Visual odometry drifts by a few percent
  /// of the path; a repeated texture "recognised" further along a corridor claims a
  /// correction as long as the path itself (measured: 100% on the corridor walk).
  double max_correction_per_path = 0.25;
  /// The direct alignment's information is scaled down so that the observed disagreement
  /// of the two directions sits at chi^2(7)'s median (6.35) when it is larger.
  double reciprocal_median = 6.35;
  /// The loop's optimisation (a large correction needs more iterations than the
  /// incremental ones after each keyframe).
  PoseGraphOptimizerOptions optimizer{
      .kernel = RobustKernel::kHuber, .kernel_width = 2.0, .max_iterations = 100};

  void Check() const;
};

/// What loop detection did for one finished keyframe.
struct LoopReport {
  int candidates = 0;  ///< database candidates above the score gates
  int consistent = 0;  ///< of them, consistent over consecutive keyframes (verified)
  int rejected = 0;    ///< verified and rejected (matches, RANSAC or direct alignment)
  std::optional<std::int64_t> loop_keyframe;  ///< the keyframe the loop closed with
  /// The loop joined two maps: this one (the new keyframe's) was merged into the
  /// candidate's, whose world frame it now shares.
  std::optional<int> merged_map;
  int ransac_inliers = 0;
  std::optional<PoseGraphSummary> optimisation;
  std::vector<std::string> rejections;  ///< why each rejected candidate failed
};

class LoopCloser {
 public:
  /// `recognizer` (the keyframes' place-recognition data) must outlive the closer.
  LoopCloser(const LoopClosureOptions& options, const PlaceRecognizer* recognizer,
             const PinholeCamera& camera);

  /// Keyframe `id` was finished, its constraints searched and its place-recognition entry
  /// added: look for a loop, adding the loop edge and optimising on success.
  LoopReport KeyframeFinished(KeyframeGraph* graph, GraphBackend* backend, std::int64_t id);

  void Clear();

 private:
  std::vector<DatabaseMatch> Candidates(const KeyframeGraph& graph, std::int64_t id,
                                        LoopReport* report) const;
  std::vector<DatabaseMatch> KeepConsistent(const KeyframeGraph& graph,
                                            const std::vector<DatabaseMatch>& candidates);
  /// ORB matches lifted with both keyframes' depth; RANSAC; direct alignment.
  std::optional<GraphBackend::Alignment> Verify(const KeyframeGraph& graph, GraphBackend* backend,
                                                std::int64_t id, std::int64_t candidate,
                                                LoopReport* report) const;
  /// Correction the loop S_cand_new implies for the new keyframe's position, as a share
  /// of the path between the two keyframes in the graph.
  static double CorrectionPerPath(const KeyframeGraph& graph, std::int64_t candidate,
                                  std::int64_t id, const Sim3d& S_cand_new);
  std::vector<PointMatch3d> LiftMatches(const KeyframeGraph& graph, std::int64_t a,
                                        std::int64_t b) const;

  LoopClosureOptions options_;
  PinholeCamera camera_;
  const PlaceRecognizer* recognizer_;
  PoseGraphOptimizer optimizer_;
  /// Groups (candidate + its connected keyframes) seen by the previous keyframe, with the
  /// number of consecutive keyframes that saw each.
  std::vector<std::pair<std::set<std::int64_t>, int>> groups_;
};

/// The keyframes connected to `id` by an edge.
std::set<std::int64_t> ConnectedKeyframes(const KeyframeGraph& graph, std::int64_t id);

}  // namespace parallax
