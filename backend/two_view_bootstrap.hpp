#pragma once
// Two-view initialisation: relative pose from ORB matches and the essential matrix.

#include <memory>
#include <optional>

#include "core/image.hpp"
#include "core/pinhole_camera.hpp"
#include "core/se3.hpp"

namespace parallax {

struct TwoViewBootstrapOptions {
  int max_features = 1500;
  float ratio_test = 0.8f;  ///< Lowe's ratio for accepting a match
  int min_inliers = 80;     ///< essential-matrix inliers with positive depth
  /// The pair is good enough when at least `parallax_points` inliers have a triangulation
  /// angle of `min_parallax_deg` or more (ORB-SLAM's rule; a median would wait forever on
  /// forward motion, where the points near the direction of travel never gain parallax).
  double min_parallax_deg = 2.0;
  /// A pair that passes every gate but has only this much parallax (or more, but below
  /// min_parallax_deg) is offered as a fallback (TryFrame's `fallback`): the start takes it when
  /// its random depth is lost before any pair is good enough (forward motion, whose parallax can
  /// peak below the bound and then fall as the near points leave the view). 0: no fallback.
  double min_fallback_parallax_deg = 1.0;
  int parallax_points = 50;
  double ransac_threshold_px = 1.0;
  /// A pair is refused while a homography explains more than this share of its inliers
  /// (transfer error under `ransac_threshold_px`): the views then do not determine the
  /// geometry (too little parallax for the scene's relief, or a plane), and the essential
  /// matrix may be a plane's twin solution (docs/math/two_view.md, "Ambiguous pairs").
  /// 1: no gate.
  double max_homography_share = 0.9;
  /// A pair is refused while another motion that the inliers' homography allows, polished on
  /// them as the pair's pose is, explains them at less than this multiple of the pair's robust
  /// cost (the essential matrix has found one of two near-equal solutions). 0: no test.
  double min_twin_cost_ratio = 1.25;
  /// A pair is refused while the turn/sideways-step ambiguity leaves the reference's inverse
  /// depths uncertain by a common offset above this (median depth 1; the pair's
  /// `inverse_depth_offset_sigma`): a start on such a pair carries the offset as a turn-rate
  /// error for as long as its depth is propagated (docs/math/two_view.md). 0: no gate.
  double max_offset_sigma = 0.008;

  void Check() const;
};

/// A reference/frame pair with enough parallax.
struct TwoViewPair {
  /// Reference-to-frame pose; translation scaled so that the median depth of the triangulated
  /// inliers in the reference is 1 (the map's normalised scale).
  SE3d T_frame_ref;
  /// Brightness change from the reference to the frame, I_frame ~ gain * I_ref + offset,
  /// fitted to 5x5 patch means around the inliers (auto-exposure between the two views).
  float gain = 1.0f;
  float offset = 0.0f;        ///< grey levels
  double parallax_deg = 0.0;  ///< the `parallax_points`-th largest triangulation angle
  /// Standard deviation of the rotation along its least determined axis, degrees
  /// (RelativePoseCovariance); and that sigma in radians divided by the baseline in
  /// median-depth units: the uncertainty of a constant added to the reference's inverse depths
  /// (median depth 1) that the turn/sideways-step ambiguity leaves (docs/math/two_view.md).
  double rotation_sigma_deg = 0.0;
  double inverse_depth_offset_sigma = 0.0;
  int inliers = 0;
};

/// Estimates the pose of a frame relative to a reference image once the motion between them
/// has enough parallax (ORB matches, essential matrix, cheirality, median triangulation angle).
class TwoViewBootstrap {
 public:
  explicit TwoViewBootstrap(const PinholeCamera& camera,
                            const TwoViewBootstrapOptions& options = {});
  ~TwoViewBootstrap();
  TwoViewBootstrap(TwoViewBootstrap&&) noexcept;
  TwoViewBootstrap& operator=(TwoViewBootstrap&&) noexcept;

  void SetReference(const ImageU8& image);
  /// The pair when it is good enough, else nullopt. When it fails only for parallax, but has
  /// at least `min_fallback_parallax_deg`, and `fallback` is not null, the pair is written
  /// there. Precondition: SetReference was called.
  std::optional<TwoViewPair> TryFrame(const ImageU8& image,
                                      std::optional<TwoViewPair>* fallback = nullptr);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace parallax
