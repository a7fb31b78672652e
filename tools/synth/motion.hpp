#pragma once
// Camera trajectories for synthetic sequences, as continuous functions of time.

#include <string>
#include <vector>

#include "core/se3.hpp"
#include "tools/synth/scene.hpp"

namespace parallax::synth {

enum class Motion {
  kShake,   ///< hand-held xyz wobble with small rotations (like TUM fr1_xyz)
  kWalk,    ///< forward walk with sway and bob along the rig's walk direction
  kOrbit,   ///< full circle around the rig's orbit centre, looking at it; ends where it began
  kRotate,  ///< sideways translation, then pure rotation in place, then translation again
  kFast,    ///< like shake, 2x amplitude and 2.5x frequency
  kPatrol,  ///< there and back along the walk direction (U-turns at both ends), repeated
};

std::vector<std::string> MotionNames();
/// "shake", "walk", "orbit", "rotate", "fast", "patrol"; throws std::invalid_argument otherwise.
Motion MotionFromString(const std::string& name);

/// Camera-to-world pose at time t in [0, duration] (seconds); continuous in t.
SE3d CameraPose(Motion motion, const CameraRig& rig, double t, double duration);

/// Rotation whose camera looks from `position` at `target` with image "down" along world +y.
SO3d LookAt(const Eigen::Vector3d& position, const Eigen::Vector3d& target);

}  // namespace parallax::synth
