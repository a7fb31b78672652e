#pragma once
// Ray-cast rendering of a Scene into a pinhole camera.

#include "core/image.hpp"
#include "core/pinhole_camera.hpp"
#include "core/se3.hpp"
#include "tools/synth/scene.hpp"

namespace parallax::synth {

/// Linear intensity (0..255, before photometric effects) and depth z along the optical axis
/// (metres; 0 where no surface is hit).
struct RenderedView {
  ImageF intensity;
  ImageF depth;
};

struct RenderOptions {
  /// 4-ray supersampling of pixels on geometry edges (textures are always mip-filtered).
  bool antialias = true;
  /// Surfaces nearer than this are clipped (metres).
  double near_plane = 0.05;
};

/// Renders `scene` seen by a camera with pose T_w_c. Each quad is rasterised over its screen
/// bounding box with an exact ray-plane intersection per pixel and a depth test, so the cost is
/// proportional to the pixels covered; then visible pixels are shaded from the mip-mapped
/// texture at the pixel's footprint (docs/synthetic.md).
RenderedView Render(const Scene& scene, const PinholeCamera& camera, const SE3d& T_w_c,
                    const RenderOptions& options = {});

}  // namespace parallax::synth
