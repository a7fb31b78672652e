#include "depth/epipolar_search.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace parallax {
namespace {

constexpr int kPatternHalf = 2;  // 5 samples
constexpr int kMaxSamples = 256 + 2 * kPatternHalf;

// Array index from a (non-negative) int position.
constexpr std::size_t Idx(int i) { return static_cast<std::size_t>(i); }

// The comparison's loops are branch-free, so that they vectorise across positions; each
// position's sum is still taken in pattern order, so the results are those of a loop that
// compares one position at a time.

/// ssd[j] = sum over k of (samples[j + k] - pattern[k])^2, for j < num_positions.
void SumsOfSquaredDifferences(const float* samples, int num_positions,
                              const std::array<float, 2 * kPatternHalf + 1>& pattern, float* ssd) {
  const float p0 = pattern[0], p1 = pattern[1], p2 = pattern[2], p3 = pattern[3], p4 = pattern[4];
  for (int j = 0; j < num_positions; ++j) {
    const float* s = samples + j;
    const float d0 = s[0] - p0, d1 = s[1] - p1, d2 = s[2] - p2, d3 = s[3] - p3, d4 = s[4] - p4;
    ssd[j] = d0 * d0 + d1 * d1 + d2 * d2 + d3 * d3 + d4 * d4;
  }
}

/// The segment's sample j at (x0 + t_j dx, y0 + t_j dy), t_j = s0 + (j - kPatternHalf), taken
/// apart as InterpolateBilinear does it: the top-left neighbour's index in a row-major image of
/// width w and the weights of its right and lower neighbours. Positions inside the image
/// (precondition). A loop of its own, which vectorises; the lookups follow in InterpolateAt.
void SegmentPositions(float x0, float y0, float dx, float dy, float s0, int n, int w, int* corner,
                      float* weight_x, float* weight_y) {
  for (int j = 0; j < n; ++j) {
    const float t = s0 + static_cast<float>(j - kPatternHalf);
    const float x = x0 + t * dx, y = y0 + t * dy;
    const int ix = static_cast<int>(x), iy = static_cast<int>(y);
    weight_x[j] = x - static_cast<float>(ix);
    weight_y[j] = y - static_cast<float>(iy);
    corner[j] = iy * w + ix;
  }
}

/// Whether mask[corner[j]] is 0 for some j < n.
bool AnyZeroAt(const std::uint8_t* mask, const int* corner, int n) {
  int zeros = 0;
  for (int j = 0; j < n; ++j) zeros += static_cast<int>(mask[corner[j]] == 0);
  return zeros > 0;
}

/// InterpolateBilinear's value at each of SegmentPositions' samples, bit for bit.
void InterpolateAt(const float* image, int w, const int* corner, const float* weight_x,
                   const float* weight_y, int n, float* samples) {
  for (int j = 0; j < n; ++j) {
    const float* row0 = image + corner[j];
    const float* row1 = row0 + w;
    const float fx = weight_x[j], fy = weight_y[j];
    samples[j] = (1.0f - fy) * ((1.0f - fx) * row0[0] + fx * row0[1]) +
                 fy * ((1.0f - fx) * row1[0] + fx * row1[1]);
  }
}

/// Index of the first smallest of values[0, n), n >= 1 (NaNs are never smaller).
int FirstMinimum(const float* values, int n) {
  int best = 0;
  for (int j = 1; j < n; ++j) {
    if (values[j] < values[best]) best = j;
  }
  return best;
}

/// How many of values[0, n) are below `threshold` more than one position away from `centre`.
/// Not inlined: inlined into Observe, GCC 12 no longer vectorises its first loop.
[[gnu::noinline]] int CountBelowAwayFrom(const float* values, int n, float threshold, int centre) {
  int below = 0;
  for (int j = 0; j < n; ++j) below += static_cast<int>(values[j] < threshold);
  for (int j = std::max(0, centre - 1); j <= std::min(n - 1, centre + 1); ++j)
    below -= static_cast<int>(values[j] < threshold);
  return below;
}

}  // namespace

EpipolarSearch::LineGeometry EpipolarSearch::MakeLineGeometry(const PinholeCamera& camera,
                                                              const SE3d& T_frame_kf,
                                                              const DepthFilterOptions& options) {
  // The frame centre in keyframe coordinates.
  const Eigen::Vector3f centre = T_frame_kf.Inverse().Translation().cast<float>();
  return {static_cast<float>(camera.Fx()),
          static_cast<float>(camera.Fy()),
          static_cast<float>(camera.Cx()),
          static_cast<float>(camera.Cy()),
          centre.x(),
          centre.y(),
          centre.z(),
          options.min_gradient_along_line_sq,
          options.min_gradient_along_line_share};
}

EpipolarSearch::EpipolarSearch(const Frame& keyframe, const StereoFrame& frame,
                               const DepthFilterOptions& options)
    : kf_(keyframe.Level(0)),
      frame_(frame.frame->IntensityLevel(0)),
      fx_(static_cast<float>(keyframe.Camera(0).Fx())),
      fy_(static_cast<float>(keyframe.Camera(0).Fy())),
      cx_(static_cast<float>(keyframe.Camera(0).Cx())),
      cy_(static_cast<float>(keyframe.Camera(0).Cy())),
      R_(frame.T_frame_kf.RotationMatrix().cast<float>()),
      t_(frame.T_frame_kf.Translation().cast<float>()),
      gain_(frame.gain),
      offset_(frame.offset),
      line_sigma_sq_(options.epipolar_line_sigma * (1.0f + frame.tracking_quality_penalty) *
                     options.epipolar_line_sigma * (1.0f + frame.tracking_quality_penalty)),
      line_geometry_(MakeLineGeometry(keyframe.Camera(0), frame.T_frame_kf, options)),
      options_(options) {}

// Branch-free (every quantity computed, the tests combined with &), so that
// MarkSearchableRow's loop vectorises.
inline EpipolarSearch::LineAtPixel EpipolarSearch::LineAt(const LineGeometry& g, int x, int y,
                                                          float gx, float gy) {
  LineAtPixel line{};
  const float qx = (static_cast<float>(x) - g.cx) / g.fx,
              qy = (static_cast<float>(y) - g.cy) / g.fy;
  // Epipolar direction in the keyframe image (towards/away from the frame centre's image),
  // normalised as Eigen's normalize() does it.
  const float lx = g.fx * (qx * g.centre_z - g.centre_x),
              ly = g.fy * (qy * g.centre_z - g.centre_y);
  const float length_sq = lx * lx + ly * ly;
  const float length = std::sqrt(length_sq);
  line.direction_x = lx / length;
  line.direction_y = ly / length;
  line.gradient_along = gx * line.direction_x + gy * line.direction_y;
  line.gradient_sq = gx * gx + gy * gy;
  const float along_sq = line.gradient_along * line.gradient_along;
  // A gradient (almost) perpendicular to the line carries no depth information.
  line.searchable = !(length_sq < 1e-12f) & !(along_sq < g.min_along_sq) &
                    !(along_sq < g.min_along_share * line.gradient_sq);
  return line;
}

void EpipolarSearch::MarkSearchableRow(int y, std::uint8_t* searchable) const {
  // Locals: the byte stores could alias members, which would then be reloaded every pixel.
  const LineGeometry geometry = line_geometry_;
  const float* dx = kf_.dx.Row(y);
  const float* dy = kf_.dy.Row(y);
  const int w = kf_.Width();
  for (int x = 0; x < w; ++x)
    searchable[x] = static_cast<std::uint8_t>(LineAt(geometry, x, y, dx[x], dy[x]).searchable);
}

StereoObservation EpipolarSearch::Observe(int x, int y, float min_idepth, float max_idepth,
                                          float expected_idepth, float max_length) const {
  StereoObservation out;
  const float w = static_cast<float>(frame_.Width()), h = static_cast<float>(frame_.Height());
  const LineAtPixel line = LineAt(line_geometry_, x, y, kf_.dx(x, y), kf_.dy(x, y));
  if (!line.searchable) return out;
  const Eigen::Vector2f line_kf(line.direction_x, line.direction_y);
  const float g_line = line.gradient_along, g_sq = line.gradient_sq;
  const Eigen::Vector3f q((static_cast<float>(x) - cx_) / fx_, (static_cast<float>(y) - cy_) / fy_,
                          1.0f);
  // The search segment: projections of the ray at min and max inverse depth.
  const Eigen::Vector3f Rq = R_ * q;
  const auto project = [&](float d) -> Eigen::Vector2f {
    const Eigen::Vector3f p = Rq + d * t_;  // = d * point
    return {fx_ * p.x() / p.z() + cx_, fy_ * p.y() / p.z() + cy_};
  };
  if (t_.z() < 0.0f) max_idepth = std::min(max_idepth, -0.99f * Rq.z() / t_.z());  // stay in front
  if (!(Rq.z() + min_idepth * t_.z() > 0.0f) || !(max_idepth > min_idepth)) {
    out.status = StereoStatus::kOutOfImage;
    return out;
  }
  Eigen::Vector2f far = project(min_idepth), near = project(max_idepth);
  Eigen::Vector2f dir = near - far;
  float length = dir.norm();
  if (length < 1e-4f) {
    dir = Eigen::Vector2f(line_kf);  // no parallax: any direction, one position
    length = 0.0f;
  } else {
    dir /= length;
  }
  // Searched interval along far + s * dir: the prior's segment padded by a pixel beyond each
  // end (a match on the prior's boundary must be an interior minimum for the sub-pixel fit; on
  // a short segment the first sample would otherwise sit on the far end and pull the estimate
  // there) and to at least min_search_length, centred (LSD-SLAM's MIN_EPL_LENGTH_CROP).
  const float pad = 1.0f + 0.5f * std::max(0.0f, options_.min_search_length - length - 2.0f);
  const float full_s0 = -pad, full_s1 = length + pad;
  float s0 = full_s0, s1 = full_s1;
  if (s1 - s0 > max_length) {  // a window centred on the expected inverse depth
    const Eigen::Vector2f expected = project(expected_idepth);
    const float centre =
        std::clamp((expected - far).dot(dir), s0 + 0.5f * max_length, s1 - 0.5f * max_length);
    s0 = centre - 0.5f * max_length;
    s1 = centre + 0.5f * max_length;
  }
  // The window must fit where the 5-sample pattern fits in the frame. A window cut by the border
  // may have lost the true match and would return the best wrong one left inside (fast forward
  // motion: near points leave the frame and would come back as far ones); DSO drops them too.
  const float lo = 2.0f + kPatternHalf, hi_x = w - 3.0f - kPatternHalf,
              hi_y = h - 3.0f - kPatternHalf;
  float in0 = -std::numeric_limits<float>::infinity(), in1 = -in0;  // s-range inside the frame
  for (int axis = 0; axis < 2; ++axis) {
    const float p0 = far[axis], d = dir[axis], hi = axis == 0 ? hi_x : hi_y;
    if (std::abs(d) < 1e-9f) {
      if (p0 < lo || p0 > hi) in1 = -std::numeric_limits<float>::infinity();
      continue;
    }
    float a = (lo - p0) / d, b = (hi - p0) / d;
    if (a > b) std::swap(a, b);
    in0 = std::max(in0, a);
    in1 = std::min(in1, b);
  }
  if (s0 < in0 || s1 > in1 || s1 < s0) {
    out.status = StereoStatus::kOutOfImage;
    return out;
  }
  // A best match at an end of a window narrower than the padded segment is no minimum: the
  // true one may lie beyond.
  const bool far_end_open = s0 > full_s0, near_end_open = s1 < full_s1;
  s0 += 0.5f * (s1 - s0 - std::floor(s1 - s0));  // whole-pixel steps, centred in the window
  // Comparison pattern: 5 keyframe samples along the line, ordered and spaced so that they
  // map onto 1-pixel steps along the frame's line at the expected depth.
  const Eigen::Vector2f x_kf(static_cast<float>(x), static_cast<float>(y));
  const auto point_at = [&](const Eigen::Vector2f& uv, float d) -> Eigen::Vector2f {
    const Eigen::Vector3f qq((uv.x() - cx_) / fx_, (uv.y() - cy_) / fy_, 1.0f);
    const Eigen::Vector3f p = R_ * qq + d * t_;
    return {fx_ * p.x() / p.z() + cx_, fy_ * p.y() / p.z() + cy_};
  };
  const Eigen::Vector2f span =
      point_at(x_kf + line_kf, expected_idepth) - point_at(x_kf - line_kf, expected_idepth);
  const float rescale = 0.5f * span.norm();
  if (rescale < options_.min_rescale || rescale > options_.max_rescale) return out;
  const Eigen::Vector2f step_kf = (span.dot(dir) >= 0.0f ? 1.0f : -1.0f) * line_kf / rescale;
  std::array<float, 2 * kPatternHalf + 1> pattern{};
  for (int k = -kPatternHalf; k <= kPatternHalf; ++k) {
    const Eigen::Vector2f p = x_kf + static_cast<float>(k) * step_kf;
    pattern[Idx(k + kPatternHalf)] =
        gain_ * InterpolateBilinear(kf_.intensity, p.x(), p.y()) + offset_;
  }
  // Frame samples along the segment at 1-pixel steps, with the pattern's margin.
  const int positions = static_cast<int>(std::floor(s1 - s0)) + 1;
  const int num_samples = std::min(positions + 2 * kPatternHalf, kMaxSamples);
  // Not value-initialised: only the first num_samples entries are written and read, and
  // zeroing these 1 KB arrays for every pixel would cost more than the search itself.
  std::array<float, kMaxSamples> samples;   // NOLINT(cppcoreguidelines-pro-type-member-init)
  std::array<int, kMaxSamples> corner;      // NOLINT(cppcoreguidelines-pro-type-member-init)
  std::array<float, kMaxSamples> weight_x;  // NOLINT(cppcoreguidelines-pro-type-member-init)
  std::array<float, kMaxSamples> weight_y;  // NOLINT(cppcoreguidelines-pro-type-member-init)
  SegmentPositions(far.x(), far.y(), dir.x(), dir.y(), s0, num_samples, frame_.Width(),
                   corner.data(), weight_x.data(), weight_y.data());
  // A window that reaches where the frame sees no input is cut as by the image border.
  if (frame_.valid != nullptr && AnyZeroAt(frame_.valid, corner.data(), num_samples)) {
    out.status = StereoStatus::kOutOfImage;
    return out;
  }
  InterpolateAt(frame_.intensity.Data(), frame_.Width(), corner.data(), weight_x.data(),
                weight_y.data(), num_samples, samples.data());
  const int num_positions = num_samples - 2 * kPatternHalf;  // >= 1
  std::array<float, kMaxSamples> ssd;  // NOLINT(cppcoreguidelines-pro-type-member-init)
  SumsOfSquaredDifferences(samples.data(), num_positions, pattern, ssd.data());
  const int best = FirstMinimum(ssd.data(), num_positions);
  out.search_length = s1 - s0;
  if ((best == 0 && far_end_open) || (best == num_positions - 1 && near_end_open) ||
      (positions > num_positions && best == num_positions - 1)) {
    out.status = StereoStatus::kNoMatch;
    return out;
  }
  const float best_ssd = ssd[Idx(best)];
  // Frame gradient along the line over the matched pattern (for the photometric error).
  float g_frame_sq = 0.0f;
  for (int k = 1; k < 2 * kPatternHalf; ++k) {
    const float g = 0.5f * (samples[Idx(best + k + 1)] - samples[Idx(best + k - 1)]);
    g_frame_sq += g * g / (2 * kPatternHalf - 1);
  }
  if (best_ssd > options_.max_ssd + 20.0f * std::sqrt(g_frame_sq * (2 * kPatternHalf + 1))) {
    out.status = StereoStatus::kNoMatch;
    return out;
  }
  if (CountBelowAwayFrom(ssd.data(), num_positions, options_.ambiguity_ratio * best_ssd, best) >
      0) {
    out.status = StereoStatus::kAmbiguous;
    return out;
  }
  // Sub-pixel: vertex of the parabola through the SSD at best - 1, best, best + 1.
  float offset_px = 0.0f;
  if (best > 0 && best + 1 < num_positions) {
    const float a = ssd[Idx(best - 1)], b = best_ssd, c = ssd[Idx(best + 1)];
    const float denom = a - 2.0f * b + c;
    if (denom > 1e-6f) offset_px = std::clamp(0.5f * (a - c) / denom, -0.5f, 0.5f);
  }
  const Eigen::Vector2f match = far + (s0 + static_cast<float>(best) + offset_px) * dir;
  // Inverse depth of the match: pi(Rq + d t) = match, solved on the better-conditioned axis.
  const auto idepth_at = [&](const Eigen::Vector2f& m) {
    if (std::abs(dir.x()) >= std::abs(dir.y())) {
      const float n = (m.x() - cx_) / fx_;
      return (n * Rq.z() - Rq.x()) / (t_.x() - n * t_.z());
    }
    const float n = (m.y() - cy_) / fy_;
    return (n * Rq.z() - Rq.y()) / (t_.y() - n * t_.z());
  };
  const float d = idepth_at(match);
  const float alpha =
      std::abs(idepth_at(match + 0.5f * dir) - idepth_at(match - 0.5f * dir));  // per pixel
  if (!(d > 0.0f) || !std::isfinite(d) || !std::isfinite(alpha) || d > options_.max_idepth) {
    out.status = StereoStatus::kOutOfImage;
    return out;
  }
  // Disparity variance: epipolar line error projected on the gradient, image noise over the
  // gradient along the line, and sub-pixel discretisation (docs/math/depth_filter.md); plus the
  // baseline's own uncertainty, which scales the inverse depth as a whole (d ~ 1 / |t|).
  const float geometric = line_sigma_sq_ * g_sq / (g_line * g_line);
  const float photometric =
      2.0f * options_.pixel_noise_sigma * options_.pixel_noise_sigma / std::max(g_frame_sq, 1.0f);
  const float baseline_relative = options_.baseline_sigma / std::max(t_.norm(), 1e-9f);
  // A rotation known to rotation_sigma of itself moves the match by that share of the
  // rotation's image motion (where a point at infinity goes); along the line it is disparity.
  const float rotation_along =
      options_.rotation_sigma > 0.0f && Rq.z() > 0.0f
          ? options_.rotation_sigma *
                (project(0.0f) - Eigen::Vector2f(static_cast<float>(x), static_cast<float>(y)))
                    .dot(dir)
          : 0.0f;
  out.status = StereoStatus::kOk;
  out.idepth = d;
  out.variance =
      alpha * alpha * (geometric + photometric + 0.05f + rotation_along * rotation_along) +
      d * d * baseline_relative * baseline_relative;
  return out;
}

}  // namespace parallax
