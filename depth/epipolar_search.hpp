#pragma once
// Stereo observation of one keyframe pixel's inverse depth along its epipolar line in another
// frame of known relative pose (docs/math/depth_filter.md).

#include <Eigen/Core>
#include <cstdint>

#include "core/frame.hpp"
#include "core/se3.hpp"
#include "depth/depth_options.hpp"

namespace parallax {

/// A tracked frame as seen from a keyframe: image, relative pose, brightness, pose quality.
struct StereoFrame {
  const Frame* frame = nullptr;
  SE3d T_frame_kf;    ///< keyframe -> frame
  float gain = 1.0f;  ///< I_frame ~= gain * I_kf + offset
  float offset = 0.0f;
  /// Extra epipolar-line uncertainty from tracking, multiplies the line sigma as (1 + q).
  float tracking_quality_penalty = 0.0f;
};

enum class StereoStatus {
  kOk,
  kSkipped,     ///< gradient not along the epipolar line, or pattern rescaled too much
  kOutOfImage,  ///< no part of the search segment is inside the frame
  kNoMatch,     ///< best SSD above the threshold
  kAmbiguous,   ///< a non-adjacent candidate almost as good as the best
};

struct StereoObservation {
  StereoStatus status = StereoStatus::kSkipped;
  float idepth = 0.0f;
  float variance = 0.0f;
  float search_length = 0.0f;  ///< pixels searched
};

/// Precomputed per (keyframe, frame) pair; cheap to copy.
class EpipolarSearch {
 public:
  EpipolarSearch(const Frame& keyframe, const StereoFrame& frame,
                 const DepthFilterOptions& options);

  /// Searches keyframe pixel (x, y) for inverse depths in [min_idepth, max_idepth] (the prior
  /// mu +- 2 sigma, or the full range for a new pixel); `expected_idepth` (> 0) orients and
  /// scales the comparison pattern, and `max_length` caps the searched segment (pixels): a
  /// window centred on the expected depth. The segment is padded by a pixel beyond each end
  /// and to at least options.min_search_length; a window that does not fit inside the frame is
  /// kOutOfImage (docs/math/depth_filter.md, "Searched segment").
  StereoObservation Observe(int x, int y, float min_idepth, float max_idepth, float expected_idepth,
                            float max_length) const;

  /// For every pixel x of keyframe row y (x < width): searchable[x] = 0 where Observe(x, y, ...)
  /// returns kSkipped before it searches (no epipolar direction there, or a gradient (almost)
  /// perpendicular to it; docs/math/depth_filter.md), else 1. Observe's own test, bit for bit,
  /// for a whole row in one loop that vectorises: a third of an update's pixels fail it.
  void MarkSearchableRow(int y, std::uint8_t* searchable) const;

 private:
  /// What Observe's first test needs: the keyframe camera, the frame centre in keyframe
  /// coordinates and the gradient gates.
  struct LineGeometry {
    float fx, fy, cx, cy;
    float centre_x, centre_y, centre_z;
    float min_along_sq, min_along_share;
  };
  /// Observe's first test at keyframe pixel (x, y) of keyframe gradient (gx, gy).
  struct LineAtPixel {
    float direction_x, direction_y;  ///< the epipolar line's unit direction
    float gradient_along;            ///< the gradient's component along it
    float gradient_sq;               ///< |gradient|^2
    bool searchable;
  };
  static LineAtPixel LineAt(const LineGeometry& geometry, int x, int y, float gx, float gy);
  static LineGeometry MakeLineGeometry(const PinholeCamera& camera, const SE3d& T_frame_kf,
                                       const DepthFilterOptions& options);

  const PyramidLevel& kf_;
  const PyramidLevel& frame_;
  float fx_, fy_, cx_, cy_;
  Eigen::Matrix3f R_;  // frame <- kf
  Eigen::Vector3f t_;
  float gain_, offset_;
  float line_sigma_sq_;
  LineGeometry line_geometry_;
  DepthFilterOptions options_;
};

}  // namespace parallax
