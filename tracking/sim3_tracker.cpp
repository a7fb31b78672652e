#include "tracking/sim3_tracker.hpp"

#include <tbb/parallel_for.h>

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <utility>
#include <vector>

#include "core/check.hpp"
#include "core/normal_equations.hpp"
#include "core/rounding.hpp"
#include "tracking/levenberg_marquardt.hpp"
#include "tracking/photometric_batch.hpp"
#include "tracking/photometric_residual.hpp"
#include "tracking/tracking_quality.hpp"

namespace parallax {
namespace {

constexpr int kParams = 9;                // 7 Sim(3) + 2 affine
constexpr std::size_t kBlockSize = 2048;  // points per deterministic partial sum

struct State {
  Sim3d S_other_ref;
  AffineBrightness affine;
};

// Dense inverse depth and variance of one level of the other keyframe (0 = none).
struct DepthLevel {
  ImageF idepth;
  ImageF variance;
};

DepthLevel Densify(const TrackingReference& reference, int level) {
  const PyramidLevel& image = reference.Keyframe().Level(level);
  DepthLevel dense{ImageF(image.Width(), image.Height(), 0.0f),
                   ImageF(image.Width(), image.Height(), 0.0f)};
  const ReferenceLevel& points = reference.Level(level);
  for (std::size_t i = 0; i < points.Size(); ++i) {
    const int x = static_cast<int>(points.u[i]), y = static_cast<int>(points.v[i]);
    dense.idepth(x, y) = points.idepth[i];
    dense.variance(x, y) = points.variance[i];
  }
  return dense;
}

struct Evaluation {
  NormalEquations<kParams> equations;
  int in_view = 0;
  int good = 0;
  int depth_residuals = 0;
  double sum_sq_residual = 0.0;
  double sum_gradient_sq = 0.0;
};

// A linearisation that keeps the level's evaluation: the finest level's, at the state the
// optimisation ends on, gives the statistics and the information matrix.
struct EvaluatedProblem : LinearizedProblem<kParams> {
  Evaluation evaluation;
};

// The depth residual's Jacobian is zero but at translation z, rotation x/y and scale
// (indices 2, 3, 4, 6). BlockAccumulator::Add with the full vector adds w J_a J_b to every
// entry; the entries left out here would get products with a zero factor, which leave a
// finite sum unchanged, so the upper triangle and g are the same bit for bit.
void AddDepthTerm(const Eigen::Vector4f& J_nonzero, float r, float w, float robust_cost,
                  BlockAccumulator<kParams>* block) {
  constexpr std::array<int, 4> kIndex = {2, 3, 4, 6};
  const Eigen::Vector4f w_J = w * J_nonzero;
  for (int b = 0; b < 4; ++b) {
    for (int a = 0; a <= b; ++a) {
      block->H(kIndex[static_cast<std::size_t>(a)], kIndex[static_cast<std::size_t>(b)]) +=
          w_J[a] * J_nonzero[b];
    }
    block->g[kIndex[static_cast<std::size_t>(b)]] += r * w_J[b];
  }
  block->cost += robust_cost;
  ++block->count;
}

/// The inverse-depth residual of point p (in the other keyframe, from reference inverse depth
/// `idepth` with variance `idepth_variance`) against the other keyframe's depth at the nearest
/// pixel; t_z is the translation's z. Returns whether the other keyframe has depth there.
bool AddDepthResidual(const Sim3TrackerOptions& options, const LevelCamera& camera,
                      const DepthLevel& depth, float t_z, const Eigen::Vector3f& p, float idepth,
                      float idepth_variance, BlockAccumulator<kParams>* block) {
  const float z = p.z();
  const int u = RoundHalfAwayFromZero(camera.fx * p.x() / z + camera.cx);
  const int v = RoundHalfAwayFromZero(camera.fy * p.y() / z + camera.cy);
  const float other_idepth = depth.idepth(u, v);
  if (!(other_idepth > 0.0f)) return false;
  const float r_d = 1.0f / z - other_idepth;
  // d(1/z)/d idepth = (z - t_z) / (z^2 idepth) (LSD-SLAM's Sim3Tracker).
  const float dd = (z - t_z) / (z * z * idepth);
  const float var_d = depth.variance(u, v) + dd * dd * idepth_variance;
  const float inv_z2 = 1.0f / (z * z);
  const Eigen::Vector4f J_d(-inv_z2, -p.y() * inv_z2, p.x() * inv_z2, -z * inv_z2);
  const RobustWeight wd = HuberWeight(r_d, var_d, options.depth_huber_threshold);
  AddDepthTerm(J_d, r_d, options.depth_weight * wd.weight, options.depth_weight * wd.cost, block);
  return true;
}

// Points [first, end) of a level, added in point order into their own partial sums.
void EvaluateBlock(const Sim3TrackerOptions& options, const ReferenceLevel& points,
                   const PyramidLevel& image, const LevelCamera& camera, const DepthLevel& depth,
                   const PhotometricModel& model, std::size_t first, std::size_t end,
                   Evaluation* e) {
  const float good_sq = options.good_threshold * options.good_threshold;
  BlockAccumulator<kParams> block;
  const auto add = [&](std::size_t i, const Eigen::Vector3f& dr_dp, const Eigen::Vector3f& p,
                       float residual, float variance, float gradient_sq, const RobustWeight& w) {
    // Photometric residual: J = [dr/dp, p x dr/dp, dr/dp . p, -exp(a) I_ref, -1].
    Eigen::Matrix<float, kParams, 1> J;
    J.head<3>() = dr_dp;
    J.segment<3>(3) = p.cross(dr_dp);
    J[6] = dr_dp.dot(p);
    J[7] = -model.gain * points.intensity[i];
    J[8] = -1.0f;
    block.Add(J, residual, w.weight, w.cost);
    ++e->in_view;
    e->good += residual * residual < good_sq * variance;
    e->sum_sq_residual += static_cast<double>(residual) * residual;
    e->sum_gradient_sq += gradient_sq;
    e->depth_residuals += AddDepthResidual(options, camera, depth, model.t.z(), p, points.idepth[i],
                                           points.variance[i], &block);
  };
  const PhotometricPoints soa{points.ray_x.data(), points.ray_y.data(), points.idepth.data(),
                              points.variance.data(), points.intensity.data()};
  ForEachPhotometricTerm(image, camera, model, soa, first, end, add);
  block.FlushInto(&e->equations);
}

Evaluation EvaluateLevel(const Sim3TrackerOptions& options, const ReferenceLevel& points,
                         const PyramidLevel& image, const PinholeCamera& K, const DepthLevel& depth,
                         const State& state) {
  const LevelCamera camera = ToLevelCamera(K);
  const Eigen::Matrix3f M =
      (state.S_other_ref.Scale() * state.S_other_ref.Rotation().Matrix()).cast<float>();
  const Eigen::Vector3f t = state.S_other_ref.Translation().cast<float>();
  const PhotometricModel model{M,
                               t,
                               state.affine.Gain(),
                               state.affine.b,
                               options.pixel_noise_sigma * options.pixel_noise_sigma,
                               options.huber_threshold};
  // Blocks of a fixed size in parallel, added in block order: the same sums for any number
  // of threads.
  const std::size_t num_blocks = (points.Size() + kBlockSize - 1) / kBlockSize;
  std::vector<Evaluation> blocks(num_blocks);
  tbb::parallel_for(std::size_t{0}, num_blocks, [&](std::size_t b) {
    EvaluateBlock(options, points, image, camera, depth, model, b * kBlockSize,
                  std::min(points.Size(), (b + 1) * kBlockSize), &blocks[b]);
  });
  Evaluation e;
  for (const Evaluation& block : blocks) {
    e.equations += block.equations;
    e.in_view += block.in_view;
    e.good += block.good;
    e.depth_residuals += block.depth_residuals;
    e.sum_sq_residual += block.sum_sq_residual;
    e.sum_gradient_sq += block.sum_gradient_sq;
  }
  return e;
}

EvaluatedProblem Linearize(const Sim3TrackerOptions& options, const ReferenceLevel& points,
                           const PyramidLevel& image, const PinholeCamera& K,
                           const DepthLevel& depth, const AffineBrightness& prior, const State& s) {
  EvaluatedProblem problem;
  problem.evaluation = EvaluateLevel(options, points, image, K, depth, s);
  const Evaluation& e = problem.evaluation;
  problem.residuals = e.in_view;
  if (e.in_view == 0) return problem;
  const double n = e.in_view;
  problem.H = e.equations.SymmetricH() / n;
  problem.g = e.equations.g / n;
  problem.cost = e.equations.cost / n;
  if (options.estimate_affine) {
    const double da = s.affine.a - prior.a, db = s.affine.b - prior.b;
    problem.H(7, 7) += options.affine_prior_a;
    problem.H(8, 8) += options.affine_prior_b;
    problem.g[7] += options.affine_prior_a * da;
    problem.g[8] += options.affine_prior_b * db;
    problem.cost += 0.5 * (options.affine_prior_a * da * da + options.affine_prior_b * db * db);
  }
  return problem;
}

State Retract(const State& s, const Eigen::Matrix<double, kParams, 1>& delta) {
  State next = s;
  next.S_other_ref = Sim3d::Exp(delta.head<7>()) * s.S_other_ref;
  next.affine.a += static_cast<float>(delta[7]);
  next.affine.b += static_cast<float>(delta[8]);
  return next;
}

/// The information of S_ref_other from the finest level's sums (raw, not per point).
Eigen::Matrix<double, 7, 7> Information(const Sim3TrackerOptions& options, const Evaluation& last,
                                        const Sim3d& S_ref_other) {
  // Marginalise the affine parameters: I = H_pp - H_pa H_aa^-1 H_ap.
  const Eigen::Matrix<double, kParams, kParams> H = last.equations.SymmetricH();
  Eigen::Matrix<double, 7, 7> info = H.topLeftCorner<7, 7>();
  if (options.estimate_affine) {
    const Eigen::Matrix2d H_aa = H.bottomRightCorner<2, 2>();
    info -= H.topRightCorner<7, 2>() * H_aa.inverse() * H.bottomLeftCorner<2, 7>();
  }
  // The Hessian is for left increments of S_other_ref; S_ref_other' = Exp(-Adj(S_ref_other)
  // delta) S_ref_other, so its information is Adj^-T H Adj^-1.
  const Eigen::Matrix<double, 7, 7> adj_inv = S_ref_other.Adjoint().inverse();
  return adj_inv.transpose() * info * adj_inv;
}

}  // namespace

void Sim3TrackerOptions::Check() const {
  const char* s = "Sim3TrackerOptions";
  CheckOption(finest_level >= 0 && finest_level < kMaxPyramidLevels, s, "finest_level",
              "must be in [0, 7]");
  CheckOption(!max_iterations.empty(), s, "max_iterations", "must not be empty");
  CheckOption(pixel_noise_sigma > 0.0f, s, "pixel_noise_sigma", "must be > 0");
  CheckOption(huber_threshold > 0.0f && depth_huber_threshold > 0.0f, s, "huber_threshold",
              "must be > 0");
  CheckOption(depth_weight >= 0.0f, s, "depth_weight", "must be >= 0");
  CheckOption(affine_prior_a >= 0.0f && affine_prior_b >= 0.0f, s, "affine_prior_a/b",
              "must be >= 0");
  CheckOption(min_good_ratio_poor <= min_good_ratio_ok, s, "min_good_ratio_poor",
              "must be <= min_good_ratio_ok");
  CheckOption(min_usage >= 0.0f && min_usage < 1.0f, s, "min_usage", "must be in [0, 1)");
}

Sim3Tracker::Sim3Tracker(const Sim3TrackerOptions& options) : options_(options) {
  options_.Check();
}

Sim3TrackingResult Sim3Tracker::Track(const TrackingReference& reference,
                                      const TrackingReference& other,
                                      const Sim3d& S_ref_other_guess,
                                      const AffineBrightness& affine_guess) const {
  CheckArgument(reference.NumLevels() == other.NumLevels() &&
                    reference.Keyframe().Level(0).Width() == other.Keyframe().Level(0).Width() &&
                    reference.Keyframe().Level(0).Height() == other.Keyframe().Level(0).Height(),
                "Sim3Tracker: the two keyframes must have the same image size and pyramid");
  State state{S_ref_other_guess.Inverse(),
              options_.estimate_affine ? affine_guess : AffineBrightness{}};
  const AffineBrightness prior = state.affine;
  const int finest = std::min(options_.finest_level, reference.NumLevels() - 1);
  CheckArgument(reference.FinestLevel() <= finest && other.FinestLevel() <= finest,
                "Sim3Tracker: a reference has no points on the tracker's finest level "
                "(TrackingReferenceOptions::finest_level)");
  Sim3TrackingResult result;
  Evaluation last;
  for (int level = reference.NumLevels() - 1; level >= finest; --level) {
    const DepthLevel depth = Densify(other, level);
    const ReferenceLevel& points = reference.Level(level);
    const PyramidLevel& image = other.Keyframe().Level(level);
    const PinholeCamera& K = other.Keyframe().Camera(level);
    const auto linearize = [&](const State& s) {
      return Linearize(options_, points, image, K, depth, prior, s);
    };
    LmSettings settings;
    settings.max_iterations = MaxIterationsForLevel(options_.max_iterations, level);
    settings.relative_tolerance = options_.relative_cost_tolerance;
    settings.min_residuals =
        std::max(20, static_cast<int>(options_.min_usage * static_cast<float>(points.Size())));
    settings.active = options_.estimate_affine ? kParams : 7;
    EvaluatedProblem final_problem;
    try {
      result.stats.iterations[static_cast<std::size_t>(level)] =
          MinimizeLevenbergMarquardt<kParams>(&state, linearize, Retract, settings, &final_problem);
    } catch (const std::invalid_argument&) {
      // A step produced a non-positive or non-finite scale: divergence, reported below.
      result.stats.diverged = true;
      break;
    }
    if (level == finest) last = std::move(final_problem.evaluation);
  }
  result.S_ref_other = state.S_other_ref.Inverse();
  result.affine = state.affine;
  result.depth_residuals = last.depth_residuals;
  TrackingStats& s = result.stats;
  const std::size_t total = reference.Level(finest).Size();
  FillPointStatistics({last.in_view, last.good, last.sum_sq_residual, last.sum_gradient_sq}, total,
                      &s);
  if (last.in_view > 0) result.information = Information(options_, last, result.S_ref_other);
  if (s.diverged ||
      last.in_view < std::max(20.0, options_.min_usage * static_cast<double>(total))) {
    s.diverged = true;
    s.reason = "diverged or too few points in view";
    result.status = TrackingStatus::kLost;
  } else {
    result.status =
        ClassifyConsistency(options_.min_good_ratio_poor, options_.min_good_ratio_ok, &s);
  }
  return result;
}

double ReciprocalMahalanobis(const Sim3TrackingResult& a_b, const Sim3TrackingResult& b_a) {
  const Eigen::Matrix<double, 7, 1> delta = (a_b.S_ref_other * b_a.S_ref_other).Log();
  const Eigen::Matrix<double, 7, 7> adj = a_b.S_ref_other.Adjoint();
  const Eigen::Matrix<double, 7, 7> covariance =
      a_b.information.inverse() + adj * b_a.information.inverse() * adj.transpose();
  return delta.dot(covariance.inverse() * delta);
}

}  // namespace parallax
