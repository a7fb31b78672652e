#pragma once
// How far a translation moves a keyframe's points in the image: the moments of its inverse
// depths that the keyframe rule's distance needs (docs/math/keyframe_rule.md).

#include <Eigen/Core>

#include "depth/depth_map.hpp"

namespace parallax {

/// Means over a keyframe's valid pixels of the smoothed inverse depth rho and of rho^2
/// weighted by the pixel's normalised image coordinates (x, y) = ((u - cx) / fx, (v - cy) / fy).
/// A translation t (keyframe coordinates, map units) moves a point by rho (t_xy - (x, y) t_z)
/// in normalised coordinates to first order, so its mean squared flow follows from these
/// five numbers without another pass over the map.
struct ParallaxMoments {
  double mean_idepth = 0.0;  ///< E[rho]
  double rho2 = 0.0;         ///< E[rho^2]
  double rho2_x = 0.0;       ///< E[rho^2 x]
  double rho2_y = 0.0;       ///< E[rho^2 y]
  double rho2_r2 = 0.0;      ///< E[rho^2 (x^2 + y^2)]

  /// The translation's distance relative to the mean depth as the image sees it:
  /// sqrt(E[rho^2 |t_xy - (x, y) t_z|^2] / E[rho^2]) * E[rho]. A translation parallel to the
  /// image plane gives |t| E[rho] (the plain relative distance); one along the optical axis
  /// counts by how far it moves the points from the image centre. 0 for an empty map.
  double ImageDistance(const Eigen::Vector3d& t_kf_frame) const;
};

/// The moments of `map`'s valid pixels in its keyframe's level-0 camera. Rows are summed in
/// parallel and added in row order: the same value for any thread count.
ParallaxMoments ComputeParallaxMoments(const InverseDepthMap& map);

}  // namespace parallax
