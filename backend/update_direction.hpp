#pragma once
// A second, map-independent estimate of a tracked frame's translation direction for the depth
// updates (docs/math/depth_filter.md, "Direction of the update pose").

#include <Eigen/Core>
#include <cstdint>
#include <memory>

#include "backend/two_view_bootstrap.hpp"
#include "core/image.hpp"
#include "core/pinhole_camera.hpp"
#include "core/se3.hpp"
#include "core/so3.hpp"

namespace parallax {

struct UpdateDirectionOptions {
  bool enabled = true;
  /// Only baselines of at least this share of the mean depth are checked (below, the
  /// essential matrix's direction is poorly conditioned and tracking is left alone).
  double min_relative_baseline = 0.03;
  /// Share of the essential-matrix direction in the blend (0 = tracking only).
  double essential_weight = 0.5;
  /// Also move the update pose's rotation the same share towards the essential matrix's
  /// relative rotation (whenever the direction is blended). Rotation and translation direction
  /// are one hypothesis: in a turn, tracking trades yaw against sideways translation (KITTI 07:
  /// 0.3-0.5 degrees of yaw with a 4-5 degree direction error), and a depth update that keeps
  /// the tracked yaw while taking the essential matrix's direction triangulates with a pose
  /// that neither view supports (docs/math/depth_filter.md, "Direction of the update pose").
  bool blend_rotation = true;
  /// The two directions must agree within this angle, degrees; otherwise tracking is kept.
  /// Wide enough to catch the drift of forward motion between sparse keyframes, where the
  /// tracked direction runs 4-11 degrees off within a few keyframes, narrow enough to refuse
  /// an essential matrix that is far off on weak texture (docs/math/depth_filter.md, "The
  /// gate's width").
  double max_angle_deg = 9.0;
  /// ORB matching and essential-matrix RANSAC (800 features, half the bootstrap's: 15% faster
  /// end to end at the same accuracy; a pair needs 0.5 degrees of parallax on 30 points and 100
  /// inliers).
  /// Only translations within this angle of the optical axis (forward or backward) are
  /// checked: the direction drift was measured on forward motion (KITTI, walks), while on
  /// sideways motion (orbits, hand-held) the check changed nothing beyond noise and cost 10-15
  /// ms per frame (docs/math/depth_filter.md).
  double max_axis_angle_deg = 45.0;
  /// Between checks the last correction (the rotation taking the tracked direction onto the
  /// blended one) is applied to later frames of the same keyframe while their tracked direction
  /// stays within `reuse_max_angle_deg` of the checked one and their baseline within a factor
  /// `recheck_growth` of the checked one; then the pair is matched again. The tracked
  /// direction's error drifts slowly, so on steady motion this halves the checks' cost.
  /// recheck_growth <= 1 checks every update.
  double recheck_growth = 1.5;
  double reuse_max_angle_deg = 5.0;
  /// ... and while the frame has turned at most this much from the checked one, degrees (in
  /// a turn, where the tracked yaw and direction go wrong together, every update is checked).
  double reuse_max_rotation_deg = 1.0;
  /// The start's ambiguity and conditioning tests are off here: each check is blended in only
  /// after agreeing with the tracked pose within max_angle_deg, which a twin solution does not.
  TwoViewBootstrapOptions matcher{.max_features = 800,
                                  .min_inliers = 100,
                                  .min_parallax_deg = 0.5,
                                  .parallax_points = 30,
                                  .max_homography_share = 1.0,
                                  .min_twin_cost_ratio = 0.0,
                                  .max_offset_sigma = 0.0};

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// Blends two unit-free translation directions: weight w of `essential`, 1 - w of `tracked`
/// (both normalised first), renormalised and given the length of `tracked`. Returns `tracked`
/// when either is zero or they are more than max_angle_deg apart.
Eigen::Vector3d BlendDirections(const Eigen::Vector3d& tracked, const Eigen::Vector3d& essential,
                                double weight, double max_angle_deg);

/// Direct tracking against a keyframe's depth map gets the translation direction from that
/// map; an error in it is written into the map by the next depth update and biases the next
/// tracking (a feedback that drifts the scale in fast forward motion). This keeps ORB features
/// of the current keyframe and, for a frame with enough baseline, blends the tracked direction
/// with the one of the essential matrix between keyframe and frame.
class UpdateDirection {
 public:
  UpdateDirection(const PinholeCamera& camera, const UpdateDirectionOptions& options);
  ~UpdateDirection();
  UpdateDirection(UpdateDirection&&) noexcept;
  UpdateDirection& operator=(UpdateDirection&&) noexcept;

  /// The keyframe later frames are compared with (its features are extracted on the first
  /// frame that needs them: many keyframes never see a long enough baseline).
  void SetKeyframe(std::int64_t keyframe_id, const ImageU8& image);
  /// Forgets the keyframe (e.g. tracking returned to an older one).
  void Reset();

  /// T_kf_frame with the blended translation direction (same length), or unchanged when the
  /// keyframe is not the one set, the baseline is short, or no reliable pair is found.
  /// `relative_baseline` = |t| x mean inverse depth of the keyframe.
  SE3d Refine(std::int64_t keyframe_id, const ImageU8& frame, const SE3d& T_kf_frame,
              double relative_baseline);

 private:
  UpdateDirectionOptions options_;
  std::unique_ptr<TwoViewBootstrap> pairs_;
  std::int64_t keyframe_id_ = -1;
  ImageU8 keyframe_image_;
  bool features_extracted_ = false;
  PinholeCamera camera_;
  // The last check on the current keyframe: its tracked direction and baseline, and the
  // correction it found (identity when the directions disagreed).
  bool has_check_ = false;
  Eigen::Vector3d checked_direction_ = Eigen::Vector3d::Zero();
  double checked_baseline_ = 0.0;
  SO3d checked_rotation_;
  SO3d correction_;           // tracked direction -> blended direction
  SO3d rotation_correction_;  // R_kf_frame tracked -> blended, applied on the left
};

}  // namespace parallax
