#pragma once
// The normal equations of SE(3) tracking with affine brightness (8 parameters), summed over
// batches of four points in four lanes (SSE2): lane k of a block sums the block's points
// 4m + k in point order, and the lanes are reduced in a fixed order, so that a level's
// evaluation does not depend on the thread count. A scalar twin does the same operations lane
// by lane; a test compares the two bit for bit (tests/tracking/photometric_batch_test.cpp).

#include <cstddef>

#include "core/normal_equations.hpp"
#include "tracking/photometric_batch.hpp"

namespace parallax {

/// Per-lane partial sums of one block of points.
struct Se3LaneSums {
  /// H's upper triangle, row by row: (0,0) (0,1) .. (0,7) (1,1) .. (7,7).
  static constexpr int kEntries = 36;
  alignas(16) float H[kEntries][4] = {};
  alignas(16) float g[8][4] = {};
  alignas(16) float cost[4] = {};
  alignas(16) double sum_sq_residual[4] = {};  ///< r^2, grey levels^2
  alignas(16) double sum_gradient_sq[4] = {};  ///< |grad I_frame|^2 at the warped points
  int in_view = 0;
  int good = 0;  ///< points with r^2 < good_sq * variance
};

/// Adds the lanes of `batch` that are in view, with the Jacobian of docs/math/tracking.md
/// J = [dr/dp, p x dr/dp, -gain I_ref, -1] (translation, rotation, log gain, offset).
/// `ref_intensity` points at the four points' keyframe intensities. SSE2.
void AddSe3Batch(const PhotometricBatch& batch, const float* ref_intensity, float gain,
                 float good_sq, Se3LaneSums* sums);

/// The scalar twin of AddSe3Batch: the same operations, lane by lane (a lane out of view adds
/// nothing; AddSe3Batch adds +0 there, which leaves every sum's bits as they are).
void AddSe3BatchScalar(const PhotometricBatch& batch, const float* ref_intensity, float gain,
                       float good_sq, Se3LaneSums* sums);

/// Evaluates points [first, first + count) of `points`, count in [1, 4], through
/// EvaluatePhotometric4 on a padded copy (the arrays need not extend past the last point);
/// `ref_intensity` receives the four lanes' keyframe intensities. Lanes >= count are not in
/// view.
void EvaluatePhotometricTail(const PyramidLevel& frame, const LevelCamera& camera,
                             const PhotometricModel& model, const PhotometricPoints& points,
                             std::size_t first, std::size_t count, PhotometricBatch* out,
                             float ref_intensity[4]);

/// Adds the four lanes of every sum into `equations` (in double, lanes in order) and the
/// counts and statistics into the other outputs.
void ReduceLaneSums(const Se3LaneSums& sums, NormalEquations<8>* equations, int* in_view, int* good,
                    double* sum_sq_residual, double* sum_gradient_sq);

}  // namespace parallax
