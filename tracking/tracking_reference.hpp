#pragma once
// The keyframe side of direct image alignment: semi-dense points with inverse depth per
// pyramid level, built once per keyframe and reused for every tracked frame.

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/frame.hpp"
#include "core/image.hpp"
#include "core/se3.hpp"

namespace parallax {

struct TrackingReferenceOptions {
  /// A level-0 pixel is used if its 3x3 max gradient magnitude is >= this (grey levels per
  /// pixel) and it has a valid inverse depth.
  float min_gradient = 5.0f;
  /// Pixels this close to the image border are not used (level 0 pixels).
  int border = 2;
  /// Point budget: each level keeps at most this many points, every k-th in raster order so
  /// that they sample the map like the full set (0: all). Tracking and keyframe alignment
  /// cost scale with it; off by default because fewer points track fast turns worse
  /// (docs/benchmarks.md, "Tracking point budget").
  std::size_t max_points_per_level = 0;
  /// Levels finer than this are left empty: building and storing level 0 (80-170k points on
  /// real texture) is wasted when the trackers stop at level 1. The coarser levels are the
  /// same either way. System sets it to the finest level its trackers use; a tracker asked
  /// for a finer level than a reference has throws.
  int finest_level = 0;

  void Check() const;
};

/// Points of one pyramid level, structure-of-arrays. Index i refers to the same point in
/// every array.
struct ReferenceLevel {
  std::vector<float> u;      ///< pixel x at this level
  std::vector<float> v;      ///< pixel y at this level
  std::vector<float> ray_x;  ///< (u - cx) / fx: the point is (ray_x, ray_y, 1) / idepth
  std::vector<float> ray_y;
  std::vector<float> idepth;     ///< inverse depth in the keyframe, 1/unit
  std::vector<float> variance;   ///< inverse-depth variance
  std::vector<float> intensity;  ///< keyframe intensity at the pixel (this level)

  std::size_t Size() const { return u.size(); }
  void Reserve(std::size_t n);
};

/// Every per-point array of a ReferenceLevel (for operations applied to all of them).
inline constexpr std::array<std::vector<float> ReferenceLevel::*, 7> kReferenceLevelFields = {
    &ReferenceLevel::u,        &ReferenceLevel::v,      &ReferenceLevel::ray_x,
    &ReferenceLevel::ray_y,    &ReferenceLevel::idepth, &ReferenceLevel::variance,
    &ReferenceLevel::intensity};

inline void ReferenceLevel::Reserve(std::size_t n) {
  for (const auto field : kReferenceLevelFields) (this->*field).reserve(n);
}

/// Keyframe-sized (level 0) inverse depth and variance, row-major, read during construction
/// only; pixels where `valid` (optional) is 0 are not used.
struct ReferenceDepth {
  int width = 0;
  int height = 0;
  const float* idepth = nullptr;
  const float* variance = nullptr;
  const std::uint8_t* valid = nullptr;
};

/// Semi-dense points of a keyframe for tracking. Level 0 takes every pixel with valid
/// inverse depth and enough gradient; level l+1 combines the (up to four) level-l points of
/// each 2x2 block by inverse-variance weighting: idepth = sum(d_i/v_i) / sum(1/v_i),
/// variance = 1 / sum(1/v_i) (docs/math/tracking.md).
class TrackingReference {
 public:
  /// `idepth` and `variance` are keyframe-sized (level 0); a pixel is valid where idepth > 0
  /// and variance > 0 (both finite). Throws std::invalid_argument on size mismatch or a null
  /// keyframe.
  TrackingReference(std::shared_ptr<const Frame> keyframe, const ImageF& idepth,
                    const ImageF& variance, const TrackingReferenceOptions& options = {});
  /// The same from arrays (a depth map's, without exporting it to images). Level 0 is scanned
  /// in parallel; the points and coarse levels do not depend on the thread count, MeanIdepth
  /// is summed per pair of rows.
  TrackingReference(std::shared_ptr<const Frame> keyframe, const ReferenceDepth& depth,
                    const TrackingReferenceOptions& options = {});

  const Frame& Keyframe() const { return *keyframe_; }
  const std::shared_ptr<const Frame>& KeyframePtr() const { return keyframe_; }
  int NumLevels() const { return static_cast<int>(levels_.size()); }
  const ReferenceLevel& Level(int level) const { return levels_[static_cast<std::size_t>(level)]; }
  /// Mean inverse depth of the level-0 points (1 after scale normalisation); of a moved
  /// reference (MovedTo), of its finest level's points.
  float MeanIdepth() const { return mean_idepth_; }
  /// The finest level with points (levels below it are empty by construction).
  int FinestLevel() const { return finest_level_; }

  /// These points moved into another frame of the same camera, level by level, for tracking
  /// while that frame's own keyframe is being made (the real-time mode's bridge,
  /// docs/realtime.md). T_to_kf: this keyframe -> `to`; gain, offset: `to`'s brightness
  /// relative to this keyframe (I_to = gain I_kf + offset). A point lands on the nearest
  /// pixel of its level, one pixel inside the border, where `to`'s intensity matches it
  /// within 20 + 0.7 |gradient| grey levels (as DepthFilter::Propagate: occluded and moving
  /// points do not); of two on one pixel the nearer stays. Inverse depth in the same unit,
  /// variance transported as (d_to / d_kf)^4; the points come in raster order.
  TrackingReference MovedTo(std::shared_ptr<const Frame> to, const SE3d& T_to_kf, float gain,
                            float offset) const;

 private:
  TrackingReference(std::shared_ptr<const Frame> keyframe, std::vector<ReferenceLevel> levels,
                    int finest_level);

  std::shared_ptr<const Frame> keyframe_;
  std::vector<ReferenceLevel> levels_;
  float mean_idepth_ = 0.0f;
  int finest_level_ = 0;
};

}  // namespace parallax
