#pragma once
// Direct Sim(3) alignment between two keyframes that both have depth: photometric and
// inverse-depth residuals (docs/math/tracking.md, "Sim(3) tracking").

#include <vector>

#include "core/sim3.hpp"
#include "tracking/tracking_reference.hpp"
#include "tracking/tracking_result.hpp"

namespace parallax {

struct Sim3TrackerOptions {
  int finest_level = 1;
  std::vector<int> max_iterations = {3, 10, 20, 40, 50};
  float pixel_noise_sigma = 4.0f;
  /// Huber thresholds on the normalised photometric and inverse-depth residuals.
  float huber_threshold = 1.5f;
  float depth_huber_threshold = 1.5f;
  /// Weight of the inverse-depth residuals relative to the photometric ones.
  float depth_weight = 1.0f;
  bool estimate_affine = true;
  float affine_prior_a = 5.0f;
  float affine_prior_b = 0.01f;
  float good_threshold = 3.0f;
  float min_good_ratio_ok = 0.6f;
  float min_good_ratio_poor = 0.35f;
  float min_usage = 0.05f;
  float relative_cost_tolerance = 1e-3f;

  void Check() const;
};

/// Result of keyframe-to-keyframe alignment.
struct Sim3TrackingResult {
  TrackingStatus status = TrackingStatus::kLost;
  /// Pose of the other keyframe in the reference keyframe's frame, including the relative
  /// scale of the two depth maps (p_ref = S_ref_other * p_other).
  Sim3d S_ref_other;
  AffineBrightness affine;
  /// Information (inverse covariance) of S_ref_other for left perturbations
  /// S' = Exp(eps) S, 7x7 in (upsilon, omega, sigma) order: the normal-equation Hessian with
  /// the affine parameters marginalised out.
  Eigen::Matrix<double, 7, 7> information = Eigen::Matrix<double, 7, 7>::Zero();
  int depth_residuals = 0;  ///< inverse-depth residuals used at the finest level
  TrackingStats stats;
};

/// Aligns the reference keyframe's points to the other keyframe (its image and inverse
/// depth), estimating S_other_ref by coarse-to-fine LM with left increments.
class Sim3Tracker {
 public:
  explicit Sim3Tracker(const Sim3TrackerOptions& options = {});

  /// `other` must have depth for the inverse-depth residuals (its TrackingReference points);
  /// throws std::invalid_argument if the two keyframes' pyramids differ in size.
  Sim3TrackingResult Track(const TrackingReference& reference, const TrackingReference& other,
                           const Sim3d& S_ref_other_guess,
                           const AffineBrightness& affine_guess = {}) const;

  const Sim3TrackerOptions& Options() const { return options_; }

 private:
  Sim3TrackerOptions options_;
};

/// LSD-SLAM's reciprocal check: with a_b tracking B against reference A and b_a tracking A
/// against reference B, Delta = Log(S_A_B * S_B_A) should be 0; returns the Mahalanobis
/// distance Delta^T (Sigma_ab + Adj(S_A_B) Sigma_ba Adj(S_A_B)^T)^-1 Delta.
double ReciprocalMahalanobis(const Sim3TrackingResult& a_b, const Sim3TrackingResult& b_a);

}  // namespace parallax
