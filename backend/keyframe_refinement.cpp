#include "backend/keyframe_refinement.hpp"

#include <tbb/parallel_for.h>

#include <Eigen/Cholesky>
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "core/check.hpp"
#include "tracking/photometric_residual.hpp"

namespace parallax {

void KeyframeRefinementOptions::Check() const {
  const char* s = "KeyframeRefinementOptions";
  CheckOption(coarsest_level >= 0 && coarsest_level < 8, s, "coarsest_level", "0..7");
  CheckOption(joint_iterations >= 0, s, "joint_iterations", ">= 0");
  CheckOption(max_joint_points >= 1, s, "max_joint_points", ">= 1");
  CheckOption(point_iterations >= 0, s, "point_iterations", ">= 0");
  CheckOption(point_frames >= 1, s, "point_frames", ">= 1");
  CheckOption(pixel_noise_sigma > 0.0f, s, "pixel_noise_sigma", "> 0");
  CheckOption(huber_k > 0.0f, s, "huber_k", "> 0");
  CheckOption(min_observations >= 1, s, "min_observations", ">= 1");
  CheckOption(max_relative_change > 0.0f && max_relative_change < 1.0f, s, "max_relative_change",
              "in (0, 1)");
  CheckOption(initial_lambda > 0.0, s, "initial_lambda", "> 0");
  CheckOption(max_pixel_step > 0.0, s, "max_pixel_step", "> 0");
  CheckOption(max_point_relative_sigma >= 0.0f && std::isfinite(max_point_relative_sigma), s,
              "max_point_relative_sigma", "finite and >= 0 (0 disables)");
}

namespace {

using Vector6f = Eigen::Matrix<float, 6, 1>;
using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

/// The points' rays (level-0 camera; the same at every level) and their keyframe grey
/// levels at one pyramid level (negative where the level has no 2x2 stencil there).
struct LevelPoints {
  std::vector<float> ray_x, ray_y, reference;
};

LevelPoints PreparePoints(const Frame& keyframe, const std::vector<std::int32_t>& pixel,
                          int level) {
  const PinholeCamera& c0 = keyframe.Camera(0);
  const PyramidLevel& lvl = keyframe.Level(level);
  const int width = keyframe.Level(0).Width();
  const float scale = 1.0f / static_cast<float>(1 << level);
  LevelPoints points;
  points.ray_x.resize(pixel.size());
  points.ray_y.resize(pixel.size());
  points.reference.resize(pixel.size());
  for (std::size_t i = 0; i < pixel.size(); ++i) {
    const int x = pixel[i] % width, y = pixel[i] / width;
    points.ray_x[i] = static_cast<float>((x - c0.Cx()) / c0.Fx());
    points.ray_y[i] = static_cast<float>((y - c0.Cy()) / c0.Fy());
    // u_l = (u_0 + 0.5) / 2^l - 0.5 (docs/conventions.md, "Pyramid").
    const float u = (static_cast<float>(x) + 0.5f) * scale - 0.5f;
    const float v = (static_cast<float>(y) + 0.5f) * scale - 0.5f;
    const bool inside = u >= 0.0f && v >= 0.0f && u < static_cast<float>(lvl.Width() - 1) &&
                        v < static_cast<float>(lvl.Height() - 1);
    points.reference[i] = inside ? InterpolateBilinear(lvl.intensity, u, v) : -1.0f;
  }
  return points;
}

/// One residual of point i in frame j, linearised: dr/d idepth and dr/d xi (left perturbation
/// of T_frame_kf, xi = (upsilon, omega)).
struct Linearised {
  float residual = 0.0f;
  float dr_dd = 0.0f;
  float pixel_rate = 0.0f;  ///< |d x' / d idepth|, level pixels per unit of inverse depth
  Vector6f J_pose;
};

/// The warp of one frame at one level.
struct FrameWarp {
  const PyramidLevel* level;
  LevelCamera camera;
  Eigen::Matrix3f R;  // R_frame_kf
  Eigen::Vector3f t;  // t_frame_kf
  float gain, offset;
};

std::vector<FrameWarp> Warps(const std::vector<RefinementFrame>& frames,
                             const std::vector<SE3d>& T_kf_frame, int level) {
  std::vector<FrameWarp> warps;
  for (std::size_t j = 0; j < frames.size(); ++j) {
    const SE3d T_frame_kf = T_kf_frame[j].Inverse();
    warps.push_back({&frames[j].frame->Level(level), ToLevelCamera(frames[j].frame->Camera(level)),
                     T_frame_kf.Rotation().Matrix().cast<float>(),
                     T_frame_kf.Translation().cast<float>(), frames[j].gain, frames[j].offset});
  }
  return warps;
}

bool Linearise(const FrameWarp& w, float ray_x, float ray_y, float idepth, float reference,
               float noise_variance, Linearised* out) {
  PhotometricTerm term;
  if (!EvaluatePhotometric(*w.level, w.camera, w.R, w.t, ray_x, ray_y, idepth, 0.0f, reference,
                           w.gain, w.offset, noise_variance, &term)) {
    return false;
  }
  out->residual = term.residual;
  // p = R ray / idepth + t: dp/d idepth = -R ray / idepth^2.
  const Eigen::Vector3f dp_dd = -(w.R * Eigen::Vector3f(ray_x, ray_y, 1.0f)) / (idepth * idepth);
  out->dr_dd = term.dr_dp.dot(dp_dd);
  const float z_inv = 1.0f / term.p.z();
  const float du = w.camera.fx * z_inv * (dp_dd.x() - term.p.x() * z_inv * dp_dd.z());
  const float dv = w.camera.fy * z_inv * (dp_dd.y() - term.p.y() * z_inv * dp_dd.z());
  out->pixel_rate = std::sqrt(du * du + dv * dv);
  out->J_pose.head<3>() = term.dr_dp;
  out->J_pose.tail<3>() = term.p.cross(term.dr_dp);
  return true;
}

/// Gain and offset of the frame's grey levels against the keyframe's at the points `which`
/// (current poses and depths), tracking's affine model re-fitted because the warp moves:
/// iteratively reweighted least squares with Huber weights, so that occluded or saturated
/// points do not pull it (a plain fit moved the KITTI hard-exposure clip past its bound).
void FitBrightness(const LevelPoints& points, const std::vector<float>& idepth,
                   const std::vector<std::size_t>& which, const KeyframeRefinementOptions& options,
                   FrameWarp* w) {
  FrameWarp unit = *w;
  unit.gain = 1.0f;
  unit.offset = 0.0f;
  std::vector<std::pair<float, float>> pairs;  // (keyframe, frame) grey levels
  for (const std::size_t i : which) {
    if (points.reference[i] < 0.0f) continue;
    Linearised l;
    if (!Linearise(unit, points.ray_x[i], points.ray_y[i], idepth[i], points.reference[i], 1.0f,
                   &l)) {
      continue;
    }
    pairs.emplace_back(points.reference[i], l.residual + points.reference[i]);
  }
  if (pairs.size() < 10) return;
  const float variance = options.pixel_noise_sigma * options.pixel_noise_sigma;
  for (int it = 0; it < 3; ++it) {
    double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (const auto& [x, y] : pairs) {
      const float r = y - (w->gain * x + w->offset);
      const double wt = HuberWeight(r, variance, options.huber_k).weight * variance;
      n += wt;
      sx += wt * x;
      sy += wt * y;
      sxx += wt * x * x;
      sxy += wt * x * y;
    }
    const double det = n * sxx - sx * sx;
    if (!(det > 1e-9 * n * n)) return;
    const double gain = (n * sxy - sx * sy) / det;
    if (!(gain > 0.1 && gain < 10.0)) return;
    w->gain = static_cast<float>(gain);
    w->offset = static_cast<float>((sy - gain * sx) / n);
  }
}

/// The warps with brightness fitted on `which`.
std::vector<FrameWarp> FittedWarps(const std::vector<RefinementFrame>& frames,
                                   const std::vector<SE3d>& T_kf_frame, int level,
                                   const LevelPoints& points, const std::vector<float>& idepth,
                                   const std::vector<std::size_t>& which,
                                   const KeyframeRefinementOptions& options) {
  std::vector<FrameWarp> warps = Warps(frames, T_kf_frame, level);
  for (FrameWarp& w : warps) FitBrightness(points, idepth, which, options, &w);
  return warps;
}

/// Huber cost of the points `which` (all when empty) over all frames.
double Cost(const std::vector<FrameWarp>& warps, const LevelPoints& points,
            const std::vector<float>& idepth, const std::vector<std::size_t>& which,
            const KeyframeRefinementOptions& options) {
  const float noise_variance = options.pixel_noise_sigma * options.pixel_noise_sigma;
  double cost = 0.0;
  for (const std::size_t i : which) {
    if (points.reference[i] < 0.0f) continue;
    for (const FrameWarp& w : warps) {
      Linearised l;
      if (!Linearise(w, points.ray_x[i], points.ray_y[i], idepth[i], points.reference[i],
                     noise_variance, &l)) {
        continue;
      }
      cost += HuberWeight(l.residual, noise_variance, options.huber_k).cost;
    }
  }
  return cost;
}

/// The joint normal equations reduced to the poses (Schur complement of the inverse depths,
/// which are independent given the poses).
struct ReducedSystem {
  Eigen::MatrixXd S;
  Eigen::VectorXd rhs;
  std::vector<double> H_dd, b_d;                         // per joint point
  std::vector<float> pixel_rate;                         // per joint point, the largest
  std::vector<std::vector<std::pair<int, Vector6d>>> h;  // per joint point: (frame, H_pose_d)
};

ReducedSystem BuildReduced(const std::vector<FrameWarp>& warps, const LevelPoints& points,
                           const std::vector<float>& idepth, const std::vector<std::size_t>& joint,
                           double lambda, const KeyframeRefinementOptions& options) {
  const int n = static_cast<int>(warps.size());
  const float noise_variance = options.pixel_noise_sigma * options.pixel_noise_sigma;
  ReducedSystem sys;
  sys.S = Eigen::MatrixXd::Zero(6 * n, 6 * n);
  sys.rhs = Eigen::VectorXd::Zero(6 * n);
  sys.H_dd.assign(joint.size(), 0.0);
  sys.b_d.assign(joint.size(), 0.0);
  sys.pixel_rate.assign(joint.size(), 0.0f);
  sys.h.resize(joint.size());
  for (std::size_t k = 0; k < joint.size(); ++k) {
    const std::size_t i = joint[k];
    if (points.reference[i] < 0.0f) continue;
    for (int j = 0; j < n; ++j) {
      Linearised l;
      if (!Linearise(warps[static_cast<std::size_t>(j)], points.ray_x[i], points.ray_y[i],
                     idepth[i], points.reference[i], noise_variance, &l)) {
        continue;
      }
      const double wgt = HuberWeight(l.residual, noise_variance, options.huber_k).weight;
      const Vector6d J = l.J_pose.cast<double>();
      sys.S.block<6, 6>(6 * j, 6 * j) += wgt * J * J.transpose();
      sys.rhs.segment<6>(6 * j) += wgt * J * l.residual;
      sys.H_dd[k] += wgt * l.dr_dd * l.dr_dd;
      sys.b_d[k] += wgt * l.dr_dd * l.residual;
      sys.h[k].emplace_back(j, wgt * J * l.dr_dd);
      sys.pixel_rate[k] = std::max(sys.pixel_rate[k], l.pixel_rate);
    }
  }
  for (int d = 0; d < 6 * n; ++d) sys.S(d, d) *= 1.0 + lambda;
  for (std::size_t k = 0; k < joint.size(); ++k) {
    if (sys.H_dd[k] <= 0.0) continue;
    const double hdd = sys.H_dd[k] * (1.0 + lambda);
    for (const auto& [a, h_a] : sys.h[k]) {
      sys.rhs.segment<6>(6 * a) -= h_a * (sys.b_d[k] / hdd);
      for (const auto& [b, h_b] : sys.h[k]) {
        if (b < a) continue;
        sys.S.block<6, 6>(6 * a, 6 * b) -= h_a * h_b.transpose() / hdd;
      }
    }
  }
  sys.S.triangularView<Eigen::StrictlyLower>() = sys.S.transpose();
  return sys;
}

/// Keeps the mean inverse depth of the joint points at `mean` (the scale gauge): inverse
/// depths times k, translations divided by k, which leaves every projection unchanged.
void HoldScale(const std::vector<std::size_t>& joint, double mean, std::vector<float>* idepth,
               std::vector<SE3d>* T_kf_frame) {
  double sum = 0.0;
  for (const std::size_t i : joint) sum += (*idepth)[i];
  const double k = mean / (sum / static_cast<double>(joint.size()));
  if (!(k > 0.0) || !std::isfinite(k)) return;
  for (const std::size_t i : joint) (*idepth)[i] = static_cast<float>((*idepth)[i] * k);
  for (SE3d& T : *T_kf_frame) T = SE3d(T.Rotation(), T.Translation() / k);
}

/// Levenberg-Marquardt on poses and the joint points' inverse depths at one level. Returns
/// the number of accepted steps.
int JointLevel(const std::vector<RefinementFrame>& frames, const LevelPoints& points,
               const std::vector<std::size_t>& joint, int level,
               const KeyframeRefinementOptions& options, std::vector<SE3d>* T_kf_frame,
               std::vector<float>* idepth) {
  double mean = 0.0;
  for (const std::size_t i : joint) mean += (*idepth)[i];
  mean /= static_cast<double>(joint.size());
  double lambda = options.initial_lambda;
  // The warps (with brightness fitted) of the current state: kept from the evaluation that
  // accepted it rather than fitted again for the next linearisation.
  std::vector<FrameWarp> warps =
      FittedWarps(frames, *T_kf_frame, level, points, *idepth, joint, options);
  double cost = Cost(warps, points, *idepth, joint, options);
  int accepted = 0;
  for (int it = 0; it < options.joint_iterations; ++it) {
    const ReducedSystem sys = BuildReduced(warps, points, *idepth, joint, lambda, options);
    const Eigen::VectorXd dx = sys.S.ldlt().solve(-sys.rhs);
    if (!dx.allFinite()) break;
    std::vector<SE3d> poses = *T_kf_frame;
    std::vector<float> depths = *idepth;
    for (std::size_t j = 0; j < poses.size(); ++j) {
      const SE3d T_frame_kf =
          SE3d::Exp(dx.segment<6>(6 * static_cast<int>(j))) * poses[j].Inverse();
      poses[j] = T_frame_kf.Inverse();
    }
    for (std::size_t k = 0; k < joint.size(); ++k) {
      if (sys.H_dd[k] <= 0.0) continue;
      double g = sys.b_d[k];
      for (const auto& [a, h_a] : sys.h[k]) g += h_a.dot(dx.segment<6>(6 * a));
      const double step = -g / (sys.H_dd[k] * (1.0 + lambda));
      const float d = depths[joint[k]];
      // Trust region per point: the linearisation holds within about a pixel.
      const double limit = options.max_pixel_step / std::max(sys.pixel_rate[k], 1e-6f);
      depths[joint[k]] = static_cast<float>(d + std::clamp(step, -limit, limit));
    }
    HoldScale(joint, mean, &depths, &poses);
    std::vector<FrameWarp> new_warps =
        FittedWarps(frames, poses, level, points, depths, joint, options);
    const double new_cost = Cost(new_warps, points, depths, joint, options);
    if (new_cost < cost) {
      cost = new_cost;
      warps = std::move(new_warps);
      *T_kf_frame = std::move(poses);
      *idepth = std::move(depths);
      lambda *= 0.5;
      ++accepted;
    } else {
      lambda *= 10.0;
    }
  }
  return accepted;
}

/// Gauss-Newton on one point's inverse depth with the poses fixed; returns the number of
/// frames it was seen in at the last evaluation.
int RefinePoint(const std::vector<FrameWarp>& warps, float ray_x, float ray_y, float reference,
                const KeyframeRefinementOptions& options, float* idepth) {
  const float noise_variance = options.pixel_noise_sigma * options.pixel_noise_sigma;
  int seen = 0;
  for (int it = 0; it < options.point_iterations; ++it) {
    double H = 0.0, b = 0.0, cost = 0.0;
    float rate = 0.0f;
    seen = 0;
    for (const FrameWarp& w : warps) {
      Linearised l;
      if (!Linearise(w, ray_x, ray_y, *idepth, reference, noise_variance, &l)) continue;
      const RobustWeight rw = HuberWeight(l.residual, noise_variance, options.huber_k);
      H += rw.weight * l.dr_dd * l.dr_dd;
      b += rw.weight * l.dr_dd * l.residual;
      cost += rw.cost;
      rate = std::max(rate, l.pixel_rate);
      ++seen;
    }
    if (!(H > 0.0)) return seen;
    const double limit = options.max_pixel_step / std::max(rate, 1e-6f);
    const auto candidate = static_cast<float>(*idepth + std::clamp(-b / H, -limit, limit));
    if (!(candidate > 0.0f)) break;
    double new_cost = 0.0;
    for (const FrameWarp& w : warps) {
      Linearised l;
      if (!Linearise(w, ray_x, ray_y, candidate, reference, noise_variance, &l)) continue;
      new_cost += HuberWeight(l.residual, noise_variance, options.huber_k).cost;
    }
    if (!(new_cost < cost)) break;
    *idepth = candidate;
  }
  return seen;
}

/// Whether the frames determine a point's inverse depth to `max_relative_sigma`: the
/// information sum_j (dr_j / dd)^2 / sigma^2 at pixel noise (no robust weight: the question is
/// what the geometry and the gradient allow, not how well the current value fits) against
/// 1 / (max_relative_sigma * d)^2.
bool Determined(const std::vector<FrameWarp>& warps, float ray_x, float ray_y, float idepth,
                float reference, float noise_variance, double max_relative_sigma) {
  double information = 0.0;
  for (const FrameWarp& w : warps) {
    Linearised l;
    if (!Linearise(w, ray_x, ray_y, idepth, reference, noise_variance, &l)) continue;
    information += static_cast<double>(l.dr_dd) * l.dr_dd / noise_variance;
  }
  const double max_sigma = max_relative_sigma * idepth;
  return information * max_sigma * max_sigma >= 1.0;
}

}  // namespace

std::vector<std::size_t> SpreadIndices(std::size_t n, std::size_t count) {
  std::vector<std::size_t> indices;
  const std::size_t m = std::min(n, count);
  for (std::size_t k = m; k-- > 0;) {
    indices.push_back(n - 1 - (k * (n - 1)) / std::max<std::size_t>(m - 1, 1));
  }
  return indices;
}

KeyframeRefinementResult RefineKeyframe(const Frame& keyframe,
                                        const std::vector<std::int32_t>& pixel,
                                        const std::vector<float>& idepth,
                                        const std::vector<RefinementFrame>& frames,
                                        const KeyframeRefinementOptions& options) {
  options.Check();
  KeyframeRefinementResult result;
  for (const RefinementFrame& f : frames) result.T_kf_frame.push_back(f.T_kf_frame);
  result.idepth = idepth;
  if (pixel.empty() || frames.empty()) return result;
  const std::size_t stride =
      (pixel.size() + static_cast<std::size_t>(options.max_joint_points) - 1) /
      static_cast<std::size_t>(options.max_joint_points);
  std::vector<std::size_t> joint;
  for (std::size_t i = 0; i < pixel.size(); i += stride) joint.push_back(i);
  result.joint_points = static_cast<int>(joint.size());
  const int coarsest = std::min(options.coarsest_level, keyframe.NumLevels() - 1);

  std::vector<float> refined = idepth;
  const LevelPoints finest = PreparePoints(keyframe, pixel, 0);
  result.initial_cost =
      Cost(FittedWarps(frames, result.T_kf_frame, 0, finest, refined, joint, options), finest,
           refined, joint, options);
  for (int level = coarsest; level >= 0; --level) {
    const LevelPoints points = level == 0 ? finest : PreparePoints(keyframe, pixel, level);
    result.iterations +=
        JointLevel(frames, points, joint, level, options, &result.T_kf_frame, &refined);
  }
  result.final_cost =
      Cost(FittedWarps(frames, result.T_kf_frame, 0, finest, refined, joint, options), finest,
           refined, joint, options);
  // Every point alone against the refined poses, coarse to fine, on at most
  // `point_frames` frames spread over the window (the last, widest baseline, included).
  // Points are independent: the parallel loop is deterministic.
  std::vector<RefinementFrame> point_frames;
  std::vector<SE3d> point_poses;
  const std::vector<std::size_t> spread =
      SpreadIndices(frames.size(), static_cast<std::size_t>(options.point_frames));
  for (auto j = spread.rbegin(); j != spread.rend(); ++j) {  // the newest first
    point_frames.push_back(frames[*j]);
    point_poses.push_back(result.T_kf_frame[*j]);
  }
  // Points the frames cannot measure (no parallax, or their gradient across the epipolar
  // lines) keep their value and are not iterated: alone, the photometric error moves them
  // by noise (docs/math/keyframe_refinement.md, "The information gate").
  std::vector<std::uint8_t> measured(pixel.size(), 1);
  if (options.max_point_relative_sigma > 0.0f) {
    const std::vector<FrameWarp> warps =
        FittedWarps(point_frames, point_poses, 0, finest, refined, joint, options);
    const float noise_variance = options.pixel_noise_sigma * options.pixel_noise_sigma;
    tbb::parallel_for(std::size_t{0}, pixel.size(), [&](std::size_t i) {
      measured[i] =
          finest.reference[i] >= 0.0f &&
          Determined(warps, finest.ray_x[i], finest.ray_y[i], refined[i], finest.reference[i],
                     noise_variance, options.max_point_relative_sigma);
    });
  }
  std::vector<int> seen(pixel.size(), 0);
  for (int level = coarsest; level >= 0; --level) {
    const LevelPoints points = level == 0 ? finest : PreparePoints(keyframe, pixel, level);
    const std::vector<FrameWarp> warps =
        FittedWarps(point_frames, point_poses, level, points, refined, joint, options);
    tbb::parallel_for(std::size_t{0}, pixel.size(), [&](std::size_t i) {
      if (points.reference[i] < 0.0f || measured[i] == 0) return;
      seen[i] = RefinePoint(warps, points.ray_x[i], points.ray_y[i], points.reference[i], options,
                            &refined[i]);
    });
  }
  for (std::size_t i = 0; i < pixel.size(); ++i) {
    const float change = std::abs(refined[i] - idepth[i]) / idepth[i];
    if (seen[i] >= options.min_observations && change <= options.max_relative_change) {
      result.idepth[i] = refined[i];
      ++result.points_refined;
    }
  }
  return result;
}

}  // namespace parallax
