#include "tracking/photometric_batch.hpp"

#include <emmintrin.h>

namespace parallax {
namespace {

__m128 Splat(float value) { return _mm_set1_ps(value); }
__m128 Negate(__m128 x) { return _mm_xor_ps(x, _mm_set1_ps(-0.0f)); }
__m128 Abs(__m128 x) { return _mm_andnot_ps(_mm_set1_ps(-0.0f), x); }
__m128 Select(__m128 mask, __m128 if_true, __m128 if_false) {
  return _mm_or_ps(_mm_and_ps(mask, if_true), _mm_andnot_ps(mask, if_false));
}

// The scalar bilinear lookups (intensity and gradient) of the lanes in `mask` at (u, v);
// returns the mask without the lanes where the frame sees no input (as outside the image).
unsigned LookUp(const PyramidLevel& frame, __m128 u, __m128 v, unsigned mask, float* intensity,
                float* gx, float* gy) {
  alignas(16) float u_lane[4], v_lane[4];
  _mm_store_ps(u_lane, u);
  _mm_store_ps(v_lane, v);
  for (int k = 0; k < 4; ++k) {
    if ((mask & (1u << k)) == 0) continue;
    const int x = static_cast<int>(u_lane[k]), y = static_cast<int>(v_lane[k]);
    if (frame.valid != nullptr && frame.valid[y * frame.Width() + x] == 0) {
      mask &= ~(1u << k);
      continue;
    }
    intensity[k] = InterpolateBilinear(frame.intensity, u_lane[k], v_lane[k]);
    gx[k] = InterpolateBilinear(frame.dx, u_lane[k], v_lane[k]);
    gy[k] = InterpolateBilinear(frame.dy, u_lane[k], v_lane[k]);
  }
  return mask;
}

// HuberWeight per lane: e = |r| / sigma; w = 1 / var, cost = e^2 / 2 inside k; w = k / (e var),
// cost = k (e - k / 2) beyond.
void StoreHuber(__m128 residual, __m128 variance, float huber_k, PhotometricBatch* out) {
  const __m128 k = Splat(huber_k), half = Splat(0.5f), one = Splat(1.0f);
  const __m128 e = _mm_div_ps(Abs(residual), _mm_sqrt_ps(variance));
  const __m128 quadratic = _mm_cmple_ps(e, k);
  _mm_store_ps(out->weight, Select(quadratic, _mm_div_ps(one, variance),
                                   _mm_div_ps(k, _mm_mul_ps(e, variance))));
  _mm_store_ps(out->cost, Select(quadratic, _mm_mul_ps(_mm_mul_ps(half, e), e),
                                 _mm_mul_ps(k, _mm_sub_ps(e, _mm_mul_ps(half, k)))));
}

}  // namespace

// Every expression below mirrors one of EvaluatePhotometric / HuberWeight, operand order
// included (IEEE addition is not associative); the bilinear lookups are the scalar ones.
void EvaluatePhotometric4(const PyramidLevel& frame, const LevelCamera& camera,
                          const PhotometricModel& model, const PhotometricPoints& points,
                          std::size_t first, PhotometricBatch* out) {
  const __m128 ray_x = _mm_loadu_ps(points.ray_x + first);
  const __m128 ray_y = _mm_loadu_ps(points.ray_y + first);
  const __m128 idepth = _mm_loadu_ps(points.idepth + first);
  const __m128 one = Splat(1.0f);
  // Mray = M (ray_x, ray_y, 1) = M0 x + (M1 y + M2); p_scaled = Mray + idepth t.
  __m128 m_ray[3], p_scaled[3];
  for (int r = 0; r < 3; ++r) {
    m_ray[r] =
        _mm_add_ps(_mm_mul_ps(Splat(model.M(r, 0)), ray_x),
                   _mm_add_ps(_mm_mul_ps(Splat(model.M(r, 1)), ray_y), Splat(model.M(r, 2))));
    p_scaled[r] = _mm_add_ps(m_ray[r], _mm_mul_ps(idepth, Splat(model.t[r])));
  }
  const __m128 in_front = _mm_cmpgt_ps(p_scaled[2], _mm_mul_ps(Splat(1e-6f), idepth));
  const __m128 inv_z = _mm_div_ps(one, p_scaled[2]);
  const __m128 xn = _mm_mul_ps(p_scaled[0], inv_z), yn = _mm_mul_ps(p_scaled[1], inv_z);
  const __m128 u = _mm_add_ps(_mm_mul_ps(Splat(camera.fx), xn), Splat(camera.cx));
  const __m128 v = _mm_add_ps(_mm_mul_ps(Splat(camera.fy), yn), Splat(camera.cy));
  const __m128 inside = _mm_and_ps(
      _mm_and_ps(_mm_cmpge_ps(u, one), _mm_cmpge_ps(v, one)),
      _mm_and_ps(_mm_cmplt_ps(u, Splat(camera.max_u)), _mm_cmplt_ps(v, Splat(camera.max_v))));
  auto mask = static_cast<unsigned>(_mm_movemask_ps(_mm_and_ps(in_front, inside)));
  alignas(16) float intensity[4] = {}, gx[4] = {}, gy[4] = {};
  mask = LookUp(frame, u, v, mask, intensity, gx, gy);
  out->in_view = mask;
  if (mask == 0) return;
  const __m128 I = _mm_load_ps(intensity), g_x = _mm_load_ps(gx), g_y = _mm_load_ps(gy);
  const __m128 z = _mm_div_ps(one, _mm_mul_ps(idepth, inv_z));
  const __m128 z_inv = _mm_mul_ps(idepth, inv_z);
  const __m128 a0 = _mm_mul_ps(_mm_mul_ps(g_x, Splat(camera.fx)), z_inv);
  const __m128 a1 = _mm_mul_ps(_mm_mul_ps(g_y, Splat(camera.fy)), z_inv);
  const __m128 a2 = Negate(_mm_add_ps(_mm_mul_ps(a0, xn), _mm_mul_ps(a1, yn)));
  _mm_store_ps(out->dr_dp[0], a0);
  _mm_store_ps(out->dr_dp[1], a1);
  _mm_store_ps(out->dr_dp[2], a2);
  _mm_store_ps(out->p[0], _mm_mul_ps(xn, z));
  _mm_store_ps(out->p[1], _mm_mul_ps(yn, z));
  _mm_store_ps(out->p[2], z);
  const __m128 reference = _mm_loadu_ps(points.ref_intensity + first);
  const __m128 residual =
      _mm_sub_ps(I, _mm_add_ps(_mm_mul_ps(Splat(model.gain), reference), Splat(model.offset)));
  // dr_dp . Mray = d0 m0 + (d1 m1 + d2 m2).
  const __m128 dot = _mm_add_ps(_mm_mul_ps(a0, m_ray[0]),
                                _mm_add_ps(_mm_mul_ps(a1, m_ray[1]), _mm_mul_ps(a2, m_ray[2])));
  const __m128 dr_dd = _mm_div_ps(Negate(dot), _mm_mul_ps(idepth, idepth));
  const __m128 variance = _mm_add_ps(
      Splat(model.pixel_noise_variance),
      _mm_mul_ps(_mm_mul_ps(dr_dd, dr_dd), _mm_loadu_ps(points.idepth_variance + first)));
  _mm_store_ps(out->residual, residual);
  _mm_store_ps(out->variance, variance);
  _mm_store_ps(out->gradient_sq, _mm_add_ps(_mm_mul_ps(g_x, g_x), _mm_mul_ps(g_y, g_y)));
  StoreHuber(residual, variance, model.huber_k, out);
}

}  // namespace parallax
