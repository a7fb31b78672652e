#include "backend/update_direction.hpp"

#include <cmath>

#include "core/angles.hpp"
#include "core/check.hpp"

namespace parallax {

void UpdateDirectionOptions::Check() const {
  const char* s = "UpdateDirectionOptions";
  CheckOption(min_relative_baseline >= 0.0, s, "min_relative_baseline", "must be >= 0");
  CheckOption(essential_weight >= 0.0 && essential_weight <= 1.0, s, "essential_weight",
              "must be in [0, 1]");
  CheckOption(max_angle_deg > 0.0 && max_angle_deg <= 180.0, s, "max_angle_deg",
              "must be in (0, 180]");
  CheckOption(std::isfinite(recheck_growth), s, "recheck_growth", "must be finite");
  CheckOption(reuse_max_angle_deg >= 0.0, s, "reuse_max_angle_deg", "must be >= 0");
  CheckOption(reuse_max_rotation_deg >= 0.0, s, "reuse_max_rotation_deg", "must be >= 0");
  CheckOption(max_axis_angle_deg >= 0.0 && max_axis_angle_deg <= 90.0, s, "max_axis_angle_deg",
              "must be in [0, 90]");
  matcher.Check();
}

Eigen::Vector3d BlendDirections(const Eigen::Vector3d& tracked, const Eigen::Vector3d& essential,
                                double weight, double max_angle_deg) {
  const double n_t = tracked.norm(), n_e = essential.norm();
  if (!(n_t > 0.0) || !(n_e > 0.0)) return tracked;
  const Eigen::Vector3d u_t = tracked / n_t, u_e = essential / n_e;
  if (AngleBetweenDeg(u_t, u_e) > max_angle_deg) return tracked;
  const Eigen::Vector3d blend = weight * u_e + (1.0 - weight) * u_t;
  return blend.normalized() * n_t;
}

UpdateDirection::UpdateDirection(const PinholeCamera& camera, const UpdateDirectionOptions& options)
    : options_(options), camera_(camera) {
  options_.Check();
}

UpdateDirection::~UpdateDirection() = default;
UpdateDirection::UpdateDirection(UpdateDirection&&) noexcept = default;
UpdateDirection& UpdateDirection::operator=(UpdateDirection&&) noexcept = default;

void UpdateDirection::SetKeyframe(std::int64_t keyframe_id, const ImageU8& image) {
  if (!options_.enabled) return;
  keyframe_image_ = image;
  features_extracted_ = false;
  keyframe_id_ = keyframe_id;
  has_check_ = false;
}

void UpdateDirection::Reset() {
  keyframe_id_ = -1;
  has_check_ = false;
}

SE3d UpdateDirection::Refine(std::int64_t keyframe_id, const ImageU8& frame, const SE3d& T_kf_frame,
                             double relative_baseline) {
  if (!options_.enabled || keyframe_id_ < 0 || keyframe_id != keyframe_id_ ||
      relative_baseline < options_.min_relative_baseline) {
    return T_kf_frame;
  }
  const Eigen::Vector3d& t = T_kf_frame.Translation();
  if (AngleBetweenDeg(t.cwiseAbs(), Eigen::Vector3d::UnitZ()) > options_.max_axis_angle_deg) {
    return T_kf_frame;
  }
  if (has_check_ && options_.recheck_growth > 1.0 &&
      relative_baseline < checked_baseline_ * options_.recheck_growth &&
      relative_baseline * options_.recheck_growth > checked_baseline_ &&
      AngleBetweenDeg(t, checked_direction_) <= options_.reuse_max_angle_deg &&
      (checked_rotation_.Inverse() * T_kf_frame.Rotation()).Log().norm() * kRadToDeg <=
          options_.reuse_max_rotation_deg) {
    return SE3d(rotation_correction_ * T_kf_frame.Rotation(), correction_ * t);
  }
  if (!pairs_) pairs_ = std::make_unique<TwoViewBootstrap>(camera_, options_.matcher);
  if (!features_extracted_) {
    pairs_->SetReference(keyframe_image_);
    features_extracted_ = true;
  }
  const std::optional<TwoViewPair> pair = pairs_->TryFrame(frame);
  if (!pair) return T_kf_frame;
  // The pair gives the keyframe-to-frame pose; the frame centre in keyframe coordinates is
  // -R^T t, the same quantity as T_kf_frame's translation.
  const Eigen::Vector3d centre =
      -(pair->T_frame_ref.Rotation().Inverse() * pair->T_frame_ref.Translation());
  const Eigen::Vector3d blended =
      BlendDirections(t, centre, options_.essential_weight, options_.max_angle_deg);
  rotation_correction_ = SO3d();
  if (options_.blend_rotation && blended != t) {
    // Geodesic blend, the same share as the direction's: R_t Exp(w Log(R_t^-1 R_e)).
    const SO3d& R_tracked = T_kf_frame.Rotation();
    const SO3d R_essential = pair->T_frame_ref.Rotation().Inverse();
    const SO3d R_blended = R_tracked * SO3d::Exp(options_.essential_weight *
                                                 (R_tracked.Inverse() * R_essential).Log());
    rotation_correction_ = R_blended * R_tracked.Inverse();
  }
  has_check_ = true;
  checked_direction_ = t;
  checked_baseline_ = relative_baseline;
  checked_rotation_ = T_kf_frame.Rotation();
  correction_ = SO3d(Eigen::Quaterniond::FromTwoVectors(t, blended));
  return SE3d(rotation_correction_ * T_kf_frame.Rotation(), blended);
}

}  // namespace parallax
