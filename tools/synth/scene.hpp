#pragma once
// Synthetic scenes: textured rectangles (boxes are six of them), world frame y down.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "tools/synth/texture.hpp"

namespace parallax::synth {

/// A textured rectangle origin + s edge_u + r edge_v, (s, r) in [0, 1]^2, with edge_u
/// perpendicular to edge_v. Visible only from the side edge_u x edge_v points to.
struct Quad {
  Eigen::Vector3d origin;
  Eigen::Vector3d edge_u;
  Eigen::Vector3d edge_v;
  int texture = 0;
  double texture_scale = 1.0;                ///< metres per texture tile
  Eigen::Vector2d texture_offset{0.0, 0.0};  ///< in tiles, so equal materials differ
  float brightness = 1.0f;                   ///< per-face shading factor
};

/// Where camera motions live in a scene (metres, world frame).
struct CameraRig {
  Eigen::Vector3d start;           ///< camera centre at t = 0
  Eigen::Vector3d look_at;         ///< point the camera looks at (shake, rotate, orbit)
  Eigen::Vector3d walk_direction;  ///< unit vector for forward walks
  double walk_speed = 1.0;         ///< m/s
  Eigen::Vector3d orbit_centre;    ///< orbits circle this point in the horizontal plane
  double orbit_radius = 1.0;
  double shake_amplitude = 0.1;  ///< m, hand-held motion
  /// Patrols: straight legs of this length along walk_direction joined by U-turns of this
  /// radius (m), walked at walk_speed (set per scene).
  double patrol_length = 2.0;
  double patrol_radius = 0.4;
};

struct Scene {
  std::string name;
  std::vector<Quad> quads;
  std::vector<Texture> textures;
  CameraRig rig;
  float sky = 215.0f;  ///< intensity where no surface is hit (depth 0)
};

/// Scene names accepted by MakeScene.
std::vector<std::string> SceneNames();

/// Builds "room", "desk", "corridor" or "street" (throws std::invalid_argument otherwise).
/// `texture_files` replace the procedural textures in order (may be empty). Deterministic for
/// a given seed.
Scene MakeScene(const std::string& name, std::uint64_t seed,
                const std::vector<std::string>& texture_files = {});

/// Adds an axis-aligned box [lo, hi]; faces point outward, or inward for a room's walls.
void AddBox(Scene* scene, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, int texture,
            double texture_scale, bool inward = false);

}  // namespace parallax::synth
