#pragma once
// ORB keypoints and binary descriptors of an image, held as plain arrays for the place
// recogniser (vocabulary, keyframe database, loop verification, relocalisation).

#include <Eigen/Core>
#include <array>
#include <bit>
#include <cstdint>
#include <vector>

#include "core/image.hpp"

namespace parallax {

/// A 256-bit ORB descriptor as four 64-bit words (bit order as OpenCV writes the bytes).
using OrbDescriptor = std::array<std::uint64_t, 4>;

/// Number of differing bits (0..256).
inline int Hamming(const OrbDescriptor& a, const OrbDescriptor& b) {
  return std::popcount(a[0] ^ b[0]) + std::popcount(a[1] ^ b[1]) + std::popcount(a[2] ^ b[2]) +
         std::popcount(a[3] ^ b[3]);
}

/// OpenCV ORB settings. The vocabulary is trained with the same settings it is used with
/// (they are part of the vocabulary's meaning; docs/place_recognition.md).
struct OrbOptions {
  int max_features = 1000;
  float scale_factor = 1.2f;  ///< between pyramid levels
  int levels = 8;
  int fast_threshold = 20;
  /// Keypoints closer than this to the border are dropped (also the descriptor patch size).
  int edge_threshold = 31;

  void Check() const;
};

/// Keypoints (level-0 pixel coordinates, pixel centres at integers), their pyramid octave,
/// orientation and descriptor; structure of arrays, one index per feature.
struct OrbFeatures {
  std::vector<Eigen::Vector2f> pixel;
  std::vector<std::uint8_t> octave;
  std::vector<float> angle_deg;
  std::vector<OrbDescriptor> descriptors;

  std::size_t Size() const { return descriptors.size(); }
  std::size_t Bytes() const;
};

/// Detects and describes up to options.max_features ORB features (deterministic for a given
/// image). An image too small for the descriptor patch gives no features.
OrbFeatures ExtractOrb(const ImageU8& image, const OrbOptions& options = {});

/// The scale of an octave's keypoint position uncertainty: scale_factor^octave pixels.
double OctaveScale(const OrbOptions& options, int octave);

}  // namespace parallax
