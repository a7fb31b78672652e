#pragma once
// Relocalisation: a frame lost against the current and recent keyframes is described with
// ORB, the keyframe database proposes keyframes showing the same place, and PnP on each
// candidate's semi-dense depth gives a pose guess for direct SE(3) confirmation
// (docs/place_recognition.md, "Relocalisation").

#include <cstdint>
#include <vector>

#include "backend/keyframe_graph.hpp"
#include "backend/place_recognizer.hpp"
#include "core/se3.hpp"

namespace parallax {

struct RelocalizationOptions {
  bool enabled = true;
  int max_candidates = 3;
  double min_score = 0.01;  ///< L1 score floor of a candidate keyframe
  int min_matches = 20;     ///< ORB matches with keyframe depth before PnP
  int min_inliers = 15;     ///< PnP RANSAC inliers
  double max_reprojection_px = 3.0;
  int ransac_iterations = 200;
  /// Keypoint depth used only when sqrt(var)/idepth is below this.
  double max_relative_depth_std = 0.2;

  void Check() const;
};

/// A pose guess of the lost frame in a keyframe, for direct confirmation.
struct RelocalizationGuess {
  std::int64_t keyframe_id = 0;
  SE3d T_kf_frame;
  int inliers = 0;
  double score = 0.0;
};

class Relocalizer {
 public:
  Relocalizer(const RelocalizationOptions& options, const PinholeCamera& camera);

  /// Guesses from the best-scoring keyframes (best first); empty when none passes the gates.
  std::vector<RelocalizationGuess> Propose(const KeyframeGraph& graph,
                                           const PlaceRecognizer& recognizer,
                                           const PlaceEntry& frame) const;
  const RelocalizationOptions& Options() const { return options_; }

 private:
  RelocalizationOptions options_;
  PinholeCamera camera_;
};

}  // namespace parallax
