#pragma once
// Tileable, mip-mapped grey textures: procedural materials or image files.

#include <cstdint>
#include <string>
#include <vector>

#include "core/image.hpp"

namespace parallax::synth {

enum class Material {
  kPlaster,  ///< multi-octave value noise (walls, ceilings)
  kTiles,    ///< square tiles with grout lines and per-tile shade (floors)
  kWood,     ///< noise-distorted rings/grain (tables, doors)
  kBricks,   ///< offset brick courses with mortar (facades)
  kPosters,  ///< overlapping rectangles and discs of many greys (posters, clutter)
  kPrint,    ///< rows of small dark marks on light paper (books, documents)
  kAsphalt,  ///< fine noise with sparse blotches (roads)
};

/// A square, power-of-two, tileable texture with its mip chain (level 0 = full size).
/// Intensities are floats in 0..255.
class Texture {
 public:
  /// Procedural material, size x size texels (power of two), deterministic for a seed.
  static Texture Procedural(Material material, int size, std::uint64_t seed);
  /// From an image file (any size; resampled to the next power of two <= 1024). Throws
  /// InputError naming the file if unreadable.
  static Texture FromFile(const std::string& path);

  int Size() const { return levels_.front().Width(); }
  int NumLevels() const { return static_cast<int>(levels_.size()); }
  /// Trilinear sample at texture coordinates (u, v) >= 0 in tiles (1.0 = one texture width;
  /// wraps), with a footprint of `texels` level-0 texels per screen pixel.
  float Sample(float u, float v, float texels) const;

 private:
  explicit Texture(ImageF base);
  float SampleLevel(int level, float u, float v) const;
  std::vector<ImageF> levels_;
};

}  // namespace parallax::synth
