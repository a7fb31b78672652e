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
  float ratio_test = 0.8f;        ///< Lowe's ratio for accepting a match
  int min_inliers = 80;           ///< essential-matrix inliers with positive depth
  double min_parallax_deg = 1.5;  ///< median triangulation angle
  double ransac_threshold_px = 1.0;

  void Check() const;
};

/// Estimates the pose of a frame relative to a reference image once the motion between them
/// has enough parallax. Translation is scaled so that the median depth of the triangulated
/// inliers in the reference is 1 (the map's normalised scale).
class TwoViewBootstrap {
 public:
  explicit TwoViewBootstrap(const PinholeCamera& camera,
                            const TwoViewBootstrapOptions& options = {});
  ~TwoViewBootstrap();
  TwoViewBootstrap(TwoViewBootstrap&&) noexcept;
  TwoViewBootstrap& operator=(TwoViewBootstrap&&) noexcept;

  void SetReference(const ImageU8& image);
  /// T_frame_ref when the pair is good enough, else nullopt.
  std::optional<SE3d> TryFrame(const ImageU8& image);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace parallax
