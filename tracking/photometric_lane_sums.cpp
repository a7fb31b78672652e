#include "tracking/photometric_lane_sums.hpp"

#include <emmintrin.h>

#include <algorithm>
#include <bit>

namespace parallax {
namespace {

// All bits of lane k set where bit k of `bits` is.
__m128 LaneMask(unsigned bits) {
  const __m128i lane_bits = _mm_set_epi32(8, 4, 2, 1);
  const __m128i selected = _mm_and_si128(_mm_set1_epi32(static_cast<int>(bits)), lane_bits);
  return _mm_castsi128_ps(_mm_cmpeq_epi32(selected, lane_bits));
}

__m128 LoadMasked(const float* lanes, __m128 mask) { return _mm_and_ps(mask, _mm_load_ps(lanes)); }

// sums[0..3] += lanes in double.
void AddInDouble(__m128 lanes, double* sums) {
  _mm_store_pd(sums, _mm_add_pd(_mm_load_pd(sums), _mm_cvtps_pd(lanes)));
  _mm_store_pd(sums + 2,
               _mm_add_pd(_mm_load_pd(sums + 2), _mm_cvtps_pd(_mm_movehl_ps(lanes, lanes))));
}

// sums[0..3] += lanes^2 in double (a float's square is exact in double).
void AddSquaresInDouble(__m128 lanes, double* sums) {
  const __m128d low = _mm_cvtps_pd(lanes), high = _mm_cvtps_pd(_mm_movehl_ps(lanes, lanes));
  _mm_store_pd(sums, _mm_add_pd(_mm_load_pd(sums), _mm_mul_pd(low, low)));
  _mm_store_pd(sums + 2, _mm_add_pd(_mm_load_pd(sums + 2), _mm_mul_pd(high, high)));
}

void Accumulate(float* lanes, __m128 value) {
  _mm_store_ps(lanes, _mm_add_ps(_mm_load_ps(lanes), value));
}

double SumLanes(const float lanes[4]) {
  double sum = lanes[0];
  for (int k = 1; k < 4; ++k) sum += static_cast<double>(lanes[k]);
  return sum;
}

}  // namespace

void AddSe3Batch(const PhotometricBatch& batch, const float* ref_intensity, float gain,
                 float good_sq, Se3LaneSums* sums) {
  // Lanes out of view have unspecified entries (possibly NaN): every input is masked to +0
  // there, so that those lanes add zeros.
  const __m128 mask = LaneMask(batch.in_view);
  const __m128 d0 = LoadMasked(batch.dr_dp[0], mask), d1 = LoadMasked(batch.dr_dp[1], mask),
               d2 = LoadMasked(batch.dr_dp[2], mask);
  const __m128 p0 = LoadMasked(batch.p[0], mask), p1 = LoadMasked(batch.p[1], mask),
               p2 = LoadMasked(batch.p[2], mask);
  const __m128 intensity = _mm_and_ps(mask, _mm_loadu_ps(ref_intensity));
  const __m128 J[8] = {d0,
                       d1,
                       d2,
                       _mm_sub_ps(_mm_mul_ps(p1, d2), _mm_mul_ps(p2, d1)),
                       _mm_sub_ps(_mm_mul_ps(p2, d0), _mm_mul_ps(p0, d2)),
                       _mm_sub_ps(_mm_mul_ps(p0, d1), _mm_mul_ps(p1, d0)),
                       _mm_xor_ps(_mm_mul_ps(_mm_set1_ps(gain), intensity), _mm_set1_ps(-0.0f)),
                       _mm_and_ps(mask, _mm_set1_ps(-1.0f))};
  const __m128 w = LoadMasked(batch.weight, mask), r = LoadMasked(batch.residual, mask);
  int entry = 0;
  for (int i = 0; i < 8; ++i) {
    const __m128 w_J = _mm_mul_ps(w, J[i]);
    for (int j = i; j < 8; ++j) Accumulate(sums->H[entry++], _mm_mul_ps(w_J, J[j]));
    Accumulate(sums->g[i], _mm_mul_ps(r, w_J));
  }
  Accumulate(sums->cost, LoadMasked(batch.cost, mask));
  AddSquaresInDouble(r, sums->sum_sq_residual);
  AddInDouble(LoadMasked(batch.gradient_sq, mask), sums->sum_gradient_sq);
  const __m128 good =
      _mm_cmplt_ps(_mm_mul_ps(r, r), _mm_mul_ps(_mm_set1_ps(good_sq), _mm_load_ps(batch.variance)));
  sums->good += std::popcount(static_cast<unsigned>(_mm_movemask_ps(_mm_and_ps(good, mask))));
  sums->in_view += std::popcount(batch.in_view);
}

void AddSe3BatchScalar(const PhotometricBatch& batch, const float* ref_intensity, float gain,
                       float good_sq, Se3LaneSums* sums) {
  for (int k = 0; k < 4; ++k) {
    if ((batch.in_view & (1u << k)) == 0) continue;
    const float d0 = batch.dr_dp[0][k], d1 = batch.dr_dp[1][k], d2 = batch.dr_dp[2][k];
    const float p0 = batch.p[0][k], p1 = batch.p[1][k], p2 = batch.p[2][k];
    const float J[8] = {d0,
                        d1,
                        d2,
                        p1 * d2 - p2 * d1,
                        p2 * d0 - p0 * d2,
                        p0 * d1 - p1 * d0,
                        -(gain * ref_intensity[k]),
                        -1.0f};
    const float w = batch.weight[k], r = batch.residual[k];
    int entry = 0;
    for (int i = 0; i < 8; ++i) {
      const float w_J = w * J[i];
      for (int j = i; j < 8; ++j) sums->H[entry++][k] += w_J * J[j];
      sums->g[i][k] += r * w_J;
    }
    sums->cost[k] += batch.cost[k];
    sums->sum_sq_residual[k] += static_cast<double>(r) * static_cast<double>(r);
    sums->sum_gradient_sq[k] += static_cast<double>(batch.gradient_sq[k]);
    sums->good += r * r < good_sq * batch.variance[k] ? 1 : 0;
    ++sums->in_view;
  }
}

void EvaluatePhotometricTail(const PyramidLevel& frame, const LevelCamera& camera,
                             const PhotometricModel& model, const PhotometricPoints& points,
                             std::size_t first, std::size_t count, PhotometricBatch* out,
                             float ref_intensity[4]) {
  float ray_x[4], ray_y[4], idepth[4], variance[4];
  for (std::size_t k = 0; k < 4; ++k) {
    const std::size_t i = first + std::min(k, count - 1);  // padded with the last point
    ray_x[k] = points.ray_x[i];
    ray_y[k] = points.ray_y[i];
    idepth[k] = points.idepth[i];
    variance[k] = points.idepth_variance[i];
    ref_intensity[k] = points.ref_intensity[i];
  }
  const PhotometricPoints padded{ray_x, ray_y, idepth, variance, ref_intensity};
  EvaluatePhotometric4(frame, camera, model, padded, 0, out);
  out->in_view &= (1u << count) - 1u;
}

void ReduceLaneSums(const Se3LaneSums& sums, NormalEquations<8>* equations, int* in_view, int* good,
                    double* sum_sq_residual, double* sum_gradient_sq) {
  int entry = 0;
  for (int i = 0; i < 8; ++i) {
    for (int j = i; j < 8; ++j) equations->H(i, j) += SumLanes(sums.H[entry++]);
    equations->g[i] += SumLanes(sums.g[i]);
  }
  equations->cost += SumLanes(sums.cost);
  equations->count += sums.in_view;
  *in_view += sums.in_view;
  *good += sums.good;
  for (int k = 0; k < 4; ++k) {
    *sum_sq_residual += sums.sum_sq_residual[k];
    *sum_gradient_sq += sums.sum_gradient_sq[k];
  }
}

}  // namespace parallax
