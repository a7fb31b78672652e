#pragma once
// Values returned by the trackers.

#include <array>
#include <cmath>
#include <string>

#include "core/se3.hpp"

namespace parallax {

/// Affine brightness relation between keyframe and frame: I_frame ~= exp(a) I_kf + b.
struct AffineBrightness {
  float a = 0.0f;  ///< log gain
  float b = 0.0f;  ///< offset, grey levels
  float Gain() const { return std::exp(a); }
};

enum class TrackingStatus {
  kOk,    ///< converged, most points consistent
  kPoor,  ///< converged but few consistent points or little overlap: usable with care
  kLost,  ///< diverged, no texture, too few points in view, or inconsistent
};
std::string ToString(TrackingStatus status);

constexpr int kMaxPyramidLevels = 8;

/// Diagnostics of one tracking call (all at the finest tracked level unless stated).
struct TrackingStats {
  double residual_rms = 0.0;      ///< grey levels, points in view
  double good_ratio = 0.0;        ///< in-view points with |r / sigma| < good threshold
  double usage = 0.0;             ///< fraction of the level's reference points in view
  double mean_gradient_sq = 0.0;  ///< mean |grad I_frame|^2 at the warped points
  int points_in_view = 0;
  int points_good = 0;  ///< in-view points with |r / sigma| < good threshold (the ratio's count)
  std::array<int, kMaxPyramidLevels> iterations{};  ///< LM iterations per level
  int hypotheses_tried = 0;
  bool diverged = false;
  std::string reason;  ///< why the status is not ok (empty when ok)
};

/// Result of SE(3) frame-to-keyframe tracking.
struct TrackingResult {
  TrackingStatus status = TrackingStatus::kLost;
  SE3d T_kf_frame;  ///< frame pose in the keyframe (p_kf = T_kf_frame * p_frame)
  AffineBrightness affine;
  TrackingStats stats;
};

}  // namespace parallax
