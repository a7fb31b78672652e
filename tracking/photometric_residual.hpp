#pragma once
// The per-point kernel of direct image alignment, shared by the SE(3) and Sim(3) trackers
// (derivation: docs/math/tracking.md).

#include <Eigen/Core>

#include "core/image.hpp"
#include "core/image_pyramid.hpp"
#include "core/pinhole_camera.hpp"

namespace parallax {

/// Projection of the frame's level camera, float.
struct LevelCamera {
  float fx, fy, cx, cy;
  float max_u, max_v;  ///< width - 2, height - 2: last positions with a valid 2x2 stencil
};

/// Float camera of a pyramid level with the last valid interpolation positions.
inline LevelCamera ToLevelCamera(const PinholeCamera& c) {
  return {static_cast<float>(c.Fx()),        static_cast<float>(c.Fy()),
          static_cast<float>(c.Cx()),        static_cast<float>(c.Cy()),
          static_cast<float>(c.Width() - 2), static_cast<float>(c.Height() - 2)};
}

/// Residual of one reference point warped into the frame.
struct PhotometricTerm {
  float residual = 0.0f;     ///< I_frame(x') - (exp(a) I_ref + b), grey levels
  float variance = 0.0f;     ///< sigma_I^2 + (dr/d idepth)^2 var(idepth)
  Eigen::Vector3f dr_dp;     ///< dr / d p_frame (1x3): grad I^T d pi / d p
  Eigen::Vector3f p;         ///< point in frame coordinates
  float gradient_sq = 0.0f;  ///< |grad I_frame(x')|^2
};

/// Warps the reference point (ray / idepth) with p = M ray / idepth + t (M = R for SE(3),
/// s R for Sim(3)) and evaluates the photometric residual. Returns false when p is behind the
/// camera, x' is not inside [1, w-2] x [1, h-2] (where gradients and bilinear lookups are
/// valid) or the frame's validity mask excludes it. Inlined: this is the hot loop.
inline bool EvaluatePhotometric(const PyramidLevel& frame, const LevelCamera& camera,
                                const Eigen::Matrix3f& M, const Eigen::Vector3f& t, float ray_x,
                                float ray_y, float idepth, float idepth_variance,
                                float ref_intensity, float gain, float offset,
                                float pixel_noise_variance, PhotometricTerm* out) {
  // Sums written out (the order Eigen's fixed-size product used on the generic x86-64 build),
  // so that the SSE2 twin (tracking/photometric_batch.cpp) can repeat them exactly.
  const Eigen::Vector3f Mray(M(0, 0) * ray_x + (M(0, 1) * ray_y + M(0, 2)),
                             M(1, 0) * ray_x + (M(1, 1) * ray_y + M(1, 2)),
                             M(2, 0) * ray_x + (M(2, 1) * ray_y + M(2, 2)));
  const Eigen::Vector3f p_scaled = Mray + idepth * t;  // = idepth * p
  if (!(p_scaled.z() > 1e-6f * idepth)) return false;
  const float inv_z = 1.0f / p_scaled.z();  // = 1 / (idepth * z)
  const float xn = p_scaled.x() * inv_z, yn = p_scaled.y() * inv_z;
  const float u = camera.fx * xn + camera.cx, v = camera.fy * yn + camera.cy;
  if (!(u >= 1.0f && v >= 1.0f && u < camera.max_u && v < camera.max_v)) {
    return false;
  }
  // Where the frame sees no input (validity mask), as outside the image.
  if (frame.valid != nullptr &&
      frame.valid[static_cast<int>(v) * frame.Width() + static_cast<int>(u)] == 0) {
    return false;
  }
  const float I = InterpolateBilinear(frame.intensity, u, v);
  const float gx = InterpolateBilinear(frame.dx, u, v);
  const float gy = InterpolateBilinear(frame.dy, u, v);
  const float z = 1.0f / (idepth * inv_z);
  const float z_inv = idepth * inv_z;  // 1 / z
  // d pi / d p = [fx/z, 0, -fx x/z^2; 0, fy/z, -fy y/z^2]
  const float a0 = gx * camera.fx * z_inv, a1 = gy * camera.fy * z_inv;
  out->dr_dp = Eigen::Vector3f(a0, a1, -(a0 * xn + a1 * yn));
  out->p = Eigen::Vector3f(xn * z, yn * z, z);
  out->residual = I - (gain * ref_intensity + offset);
  // d p / d idepth = -(p - t) / idepth = -M ray / idepth^2.
  const Eigen::Vector3f& d = out->dr_dp;
  const float dr_dd =
      -(d.x() * Mray.x() + (d.y() * Mray.y() + d.z() * Mray.z())) / (idepth * idepth);
  out->variance = pixel_noise_variance + dr_dd * dr_dd * idepth_variance;
  out->gradient_sq = gx * gx + gy * gy;
  return true;
}

/// Huber weight and cost of a residual r with standard deviation sigma (normalised
/// threshold k): weight w such that w * r^2 / 2 = cost near 0.
struct RobustWeight {
  float weight;  ///< multiplies J^T J and J^T r
  float cost;    ///< Huber cost of r / sigma
};
inline RobustWeight HuberWeight(float residual, float variance, float k) {
  const float e = std::abs(residual) / std::sqrt(variance);
  if (e <= k) return {1.0f / variance, 0.5f * e * e};
  return {k / (e * variance), k * (e - 0.5f * k)};
}

}  // namespace parallax
