#include "depth/regularize_kernel.hpp"

#include <algorithm>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace parallax {
namespace {

/// Five running sums, for one lane (column of the window).
struct Sums {
  float support = 0.0f, agree = 0.0f, disagree = 0.0f, w = 0.0f, wd = 0.0f;
};

/// Adds neighbour j of the centre (d_i, var_i); `votes` is false for the centre itself.
inline void AddNeighbour(const RegularizeInputs& in, std::size_t j, float d_i, float var_i,
                         float decay, bool votes, Sums* s) {
  const float d_j = in.idepth[j];
  const float diff = d_j - d_i;
  const bool compatible = in.inv_var[j] > 0.0f && diff * diff <= var_i + in.variance[j];
  const float vote = votes ? in.vote[j] : 0.0f;
  s->support += in.support[j];
  s->agree += compatible ? vote : 0.0f;
  s->disagree += compatible ? 0.0f : vote;
  const float weight = in.inv_var[j] * decay;
  s->w += compatible ? weight : 0.0f;
  s->wd += compatible ? weight * d_j : 0.0f;
}

RegularizedPixel Finish(const std::array<Sums, 4>& lanes, const Sums& fifth, float var_i) {
  const auto total = [&](float Sums::*field) {
    return ((lanes[0].*field + lanes[1].*field) + (lanes[2].*field + lanes[3].*field)) +
           fifth.*field;
  };
  RegularizedPixel out;
  const float sum_w = total(&Sums::w);
  out.idepth = total(&Sums::wd) / sum_w;
  out.variance = std::min(var_i, 1.0f / sum_w);
  out.support = total(&Sums::support);
  out.agree = total(&Sums::agree);
  out.disagree = total(&Sums::disagree);
  return out;
}

}  // namespace

RegularizedPixel RegularizePixelScalar(const RegularizeInputs& in, std::size_t i) {
  const float d_i = in.idepth[i], var_i = in.variance[i];
  std::array<Sums, 4> lanes{};
  Sums fifth;
  const auto w = static_cast<std::size_t>(in.width);
  for (std::size_t r = 0; r < 5; ++r) {
    const std::size_t row = i - 2 * w - 2 + r * w;  // window row r (dy = r - 2), dx = -2
    const float* decay = &in.decay[r * 5];
    for (std::size_t k = 0; k < 4; ++k) {
      AddNeighbour(in, row + k, d_i, var_i, decay[k], r != 2 || k != 2, &lanes[k]);
    }
    AddNeighbour(in, row + 4, d_i, var_i, decay[4], true, &fifth);
  }
  return Finish(lanes, fifth, var_i);
}

#if defined(__SSE2__)
RegularizedPixel RegularizePixelSimd(const RegularizeInputs& in, std::size_t i) {
  const float d_i = in.idepth[i], var_i = in.variance[i];
  const __m128 d_c = _mm_set1_ps(d_i), var_c = _mm_set1_ps(var_i), zero = _mm_setzero_ps();
  // The centre (row 0, lane 2) does not vote on itself.
  const __m128 centre_row_votes = _mm_castsi128_ps(_mm_set_epi32(-1, 0, -1, -1));
  __m128 support = zero, agree = zero, disagree = zero, sum_w = zero, sum_wd = zero;
  Sums fifth;
  const auto w = static_cast<std::size_t>(in.width);
  for (std::size_t r = 0; r < 5; ++r) {
    const std::size_t row = i - 2 * w - 2 + r * w;  // window row r (dy = r - 2), dx = -2
    const float* decay = &in.decay[r * 5];
    const __m128 d = _mm_loadu_ps(in.idepth + row);
    const __m128 var = _mm_loadu_ps(in.variance + row);
    const __m128 inv_var = _mm_loadu_ps(in.inv_var.data() + row);
    __m128 vote = _mm_loadu_ps(in.vote.data() + row);
    if (r == 2) vote = _mm_and_ps(vote, centre_row_votes);
    const __m128 diff = _mm_sub_ps(d, d_c);
    const __m128 compatible = _mm_and_ps(
        _mm_cmpgt_ps(inv_var, zero), _mm_cmple_ps(_mm_mul_ps(diff, diff), _mm_add_ps(var_c, var)));
    support = _mm_add_ps(support, _mm_loadu_ps(in.support.data() + row));
    agree = _mm_add_ps(agree, _mm_and_ps(compatible, vote));
    disagree = _mm_add_ps(disagree, _mm_andnot_ps(compatible, vote));
    const __m128 weight = _mm_mul_ps(inv_var, _mm_loadu_ps(decay));
    sum_w = _mm_add_ps(sum_w, _mm_and_ps(compatible, weight));
    sum_wd = _mm_add_ps(sum_wd, _mm_and_ps(compatible, _mm_mul_ps(weight, d)));
    AddNeighbour(in, row + 4, d_i, var_i, decay[4], true, &fifth);
  }
  // ((lane0 + lane1) + (lane2 + lane3)) + column 5, as the scalar twin adds them.
  const auto total = [](__m128 v, float fifth_sum) {
    const __m128 pairs = _mm_add_ps(v, _mm_shuffle_ps(v, v, _MM_SHUFFLE(2, 3, 0, 1)));
    const __m128 four = _mm_add_ss(pairs, _mm_movehl_ps(pairs, pairs));
    return _mm_cvtss_f32(four) + fifth_sum;
  };
  RegularizedPixel out;
  const float w_total = total(sum_w, fifth.w);
  out.idepth = total(sum_wd, fifth.wd) / w_total;
  out.variance = std::min(var_i, 1.0f / w_total);
  out.support = total(support, fifth.support);
  out.agree = total(agree, fifth.agree);
  out.disagree = total(disagree, fifth.disagree);
  return out;
}
#else
RegularizedPixel RegularizePixelSimd(const RegularizeInputs& in, std::size_t i) {
  return RegularizePixelScalar(in, i);
}
#endif

}  // namespace parallax
