#pragma once
// Four reference points through the photometric kernel at once (SSE2). Each lane does the
// operations of EvaluatePhotometric and HuberWeight (tracking/photometric_residual.hpp) in
// the same order, so its results equal the scalar twin's bit for bit; a test compares them
// (tests/tracking/photometric_batch_test.cpp).

#include <Eigen/Core>
#include <cstdint>

#include "tracking/photometric_residual.hpp"

namespace parallax {

/// The per-point inputs of a reference level (structure of arrays, 4 entries each read).
struct PhotometricPoints {
  const float* ray_x;
  const float* ray_y;
  const float* idepth;
  const float* idepth_variance;
  const float* ref_intensity;
};

/// The warp and brightness model shared by the lanes.
struct PhotometricModel {
  Eigen::Matrix3f M;  ///< R for SE(3), s R for Sim(3)
  Eigen::Vector3f t;
  float gain = 1.0f;
  float offset = 0.0f;
  float pixel_noise_variance = 1.0f;
  float huber_k = 1.0f;
};

/// Results of four points; entries of lanes not in `in_view` are unspecified.
struct PhotometricBatch {
  unsigned in_view = 0;  ///< bit k set: lane k is inside the image (EvaluatePhotometric true)
  alignas(16) float dr_dp[3][4];
  alignas(16) float p[3][4];
  alignas(16) float residual[4];
  alignas(16) float variance[4];
  alignas(16) float gradient_sq[4];
  alignas(16) float weight[4];  ///< HuberWeight(residual, variance, huber_k)
  alignas(16) float cost[4];
};

/// Points first .. first+3 of `points`, warped into `frame` (see EvaluatePhotometric).
void EvaluatePhotometric4(const PyramidLevel& frame, const LevelCamera& camera,
                          const PhotometricModel& model, const PhotometricPoints& points,
                          std::size_t first, PhotometricBatch* out);

/// Calls add(i, dr_dp, p, residual, variance, gradient_sq, RobustWeight) for every point
/// i in [first, end) that lands inside `frame`, in point order: four at a time through
/// EvaluatePhotometric4, the remainder through its scalar twin (the same results either way).
template <typename Add>
void ForEachPhotometricTerm(const PyramidLevel& frame, const LevelCamera& camera,
                            const PhotometricModel& model, const PhotometricPoints& points,
                            std::size_t first, std::size_t end, Add&& add) {
  std::size_t i = first;
  PhotometricBatch batch;
  for (; i + 4 <= end; i += 4) {
    EvaluatePhotometric4(frame, camera, model, points, i, &batch);
    for (std::size_t lane = 0; lane < 4; ++lane) {
      if ((batch.in_view & (1u << lane)) == 0) continue;
      add(i + lane,
          Eigen::Vector3f(batch.dr_dp[0][lane], batch.dr_dp[1][lane], batch.dr_dp[2][lane]),
          Eigen::Vector3f(batch.p[0][lane], batch.p[1][lane], batch.p[2][lane]),
          batch.residual[lane], batch.variance[lane], batch.gradient_sq[lane],
          RobustWeight{batch.weight[lane], batch.cost[lane]});
    }
  }
  PhotometricTerm term;
  for (; i < end; ++i) {
    if (EvaluatePhotometric(frame, camera, model.M, model.t, points.ray_x[i], points.ray_y[i],
                            points.idepth[i], points.idepth_variance[i], points.ref_intensity[i],
                            model.gain, model.offset, model.pixel_noise_variance, &term)) {
      add(i, term.dr_dp, term.p, term.residual, term.variance, term.gradient_sq,
          HuberWeight(term.residual, term.variance, model.huber_k));
    }
  }
}

}  // namespace parallax
