#pragma once
// 3-D points for image keypoints from a keyframe's frozen semi-dense depth (loop
// verification and relocalisation lift ORB keypoints with it).

#include <Eigen/Core>
#include <optional>

#include "backend/keyframe_graph.hpp"
#include "core/image.hpp"
#include "core/pinhole_camera.hpp"

namespace parallax {

class KeypointDepth {
 public:
  /// `max_relative_std`: an estimate is used only when sqrt(variance) / idepth is below it.
  KeypointDepth(const FrozenDepth& depth, const PinholeCamera& camera, double max_relative_std);

  /// The point (keyframe coordinates) of the most certain estimate within one pixel of
  /// `pixel`, or nullopt when there is none certain enough.
  std::optional<Eigen::Vector3d> Point(const Eigen::Vector2f& pixel) const;

 private:
  ImageF idepth_;
  ImageF variance_;
  PinholeCamera camera_;
  double max_relative_std_;
};

}  // namespace parallax
