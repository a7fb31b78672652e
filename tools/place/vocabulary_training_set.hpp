#pragma once
// The images a vocabulary is trained on: generic photographs, each seen at the engine's
// working resolution and through deterministic augmentations (zoomed crops, in-plane
// rotations, gamma, blur), so that words cover the appearance changes a revisit brings
// (docs/place_recognition.md, "Training").

#include <string>
#include <vector>

#include "backend/orb_features.hpp"
#include "core/image.hpp"

namespace parallax {

struct TrainingSetOptions {
  /// Every photograph is first scaled to fit this size (the engine's typical input).
  int width = 640;
  int height = 480;
  /// Magnifications of the fitted photograph: each gives its centre and four corner crops
  /// of width x height.
  std::vector<double> zooms = {1.6, 2.5};
  std::vector<double> rotations_deg = {-15.0, 15.0};
  std::vector<double> gammas = {0.6, 1.6};
  double blur_sigma = 1.5;  ///< one blurred copy (motion, defocus); 0: none
  OrbOptions orb;

  void Check() const;
};

/// The augmented views of one grey photograph, in a fixed order (the fitted image first).
std::vector<ImageU8> AugmentedViews(const ImageU8& photo, const TrainingSetOptions& options);

/// ORB descriptors of every augmented view of every image file (one vector per view).
/// Throws InputError naming a file that cannot be read.
std::vector<std::vector<OrbDescriptor>> TrainingDescriptors(const std::vector<std::string>& paths,
                                                            const TrainingSetOptions& options);

}  // namespace parallax
