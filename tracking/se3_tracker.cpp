#include "tracking/se3_tracker.hpp"

#include <tbb/parallel_for.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "core/angles.hpp"
#include "core/check.hpp"
#include "tracking/levenberg_marquardt.hpp"
#include "tracking/photometric_batch.hpp"
#include "tracking/photometric_lane_sums.hpp"
#include "tracking/photometric_residual.hpp"
#include "tracking/tracking_quality.hpp"

namespace parallax {
namespace {

constexpr std::size_t kBlockSize = 2048;  // points per deterministic partial sum

// A linearisation that keeps the level's evaluation (statistics included), so that the state
// the optimisation ends on need not be evaluated again.
struct EvaluatedProblem : LinearizedProblem<8> {
  Se3Tracker::LevelEvaluation evaluation;
};

// Points [first, end) of a level, four at a time in four lanes of sums
// (tracking/photometric_lane_sums.hpp).
void EvaluateBlock(const PyramidLevel& image, const LevelCamera& camera,
                   const PhotometricModel& model, const ReferenceLevel& points, float good_sq,
                   std::size_t first, std::size_t end, Se3Tracker::LevelEvaluation* sum) {
  const PhotometricPoints soa{points.ray_x.data(), points.ray_y.data(), points.idepth.data(),
                              points.variance.data(), points.intensity.data()};
  Se3LaneSums lanes;
  PhotometricBatch batch;
  std::size_t i = first;
  for (; i + 4 <= end; i += 4) {
    EvaluatePhotometric4(image, camera, model, soa, i, &batch);
    if (batch.in_view != 0) AddSe3Batch(batch, soa.ref_intensity + i, model.gain, good_sq, &lanes);
  }
  if (i < end) {
    float ref_intensity[4];
    EvaluatePhotometricTail(image, camera, model, soa, i, end - i, &batch, ref_intensity);
    if (batch.in_view != 0) AddSe3Batch(batch, ref_intensity, model.gain, good_sq, &lanes);
  }
  ReduceLaneSums(lanes, &sum->equations, &sum->in_view, &sum->good, &sum->sum_sq_residual,
                 &sum->sum_gradient_sq);
}

}  // namespace

std::string ToString(TrackingStatus status) {
  switch (status) {
    case TrackingStatus::kOk:
      return "ok";
    case TrackingStatus::kPoor:
      return "poor";
    case TrackingStatus::kLost:
      return "lost";
  }
  return "lost";
}

void Se3TrackerOptions::Check() const {
  const char* s = "Se3TrackerOptions";
  CheckOption(finest_level >= 0 && finest_level < kMaxPyramidLevels, s, "finest_level",
              "must be in [0, 7]");
  CheckOption(!max_iterations.empty(), s, "max_iterations", "must not be empty");
  for (const int n : max_iterations)
    CheckOption(n >= 0, s, "max_iterations", "entries must be >= 0");
  CheckOption(pixel_noise_sigma > 0.0f, s, "pixel_noise_sigma", "must be > 0");
  CheckOption(huber_threshold > 0.0f, s, "huber_threshold", "must be > 0");
  CheckOption(affine_prior_a >= 0.0f && affine_prior_b >= 0.0f, s, "affine_prior_a/b",
              "must be >= 0");
  CheckOption(max_abs_affine_a > 0.0f, s, "max_abs_affine_a", "must be > 0");
  CheckOption(good_threshold > 0.0f, s, "good_threshold", "must be > 0");
  CheckOption(min_good_ratio_poor <= min_good_ratio_ok, s, "min_good_ratio_poor",
              "must be <= min_good_ratio_ok");
  CheckOption(min_usage >= 0.0f && min_usage <= min_usage_ok, s, "min_usage",
              "must be in [0, min_usage_ok]");
  CheckOption(relative_cost_tolerance >= 0.0f, s, "relative_cost_tolerance", "must be >= 0");
  CheckOption(hypothesis_iterations >= 0, s, "hypothesis_iterations", "must be >= 0");
  CheckOption(suspect_good_ratio >= 0.0f && suspect_good_ratio <= 1.0f, s, "suspect_good_ratio",
              "must be in [0, 1] (0 disables)");
  CheckOption(!search_rotations_deg.empty(), s, "search_rotations_deg", "must not be empty");
  for (const double angle : search_rotations_deg) {
    CheckOption(std::isfinite(angle) && angle > 0.0 && angle < 90.0, s, "search_rotations_deg",
                "must be in (0, 90)");
  }
  CheckOption(velocity_rescale_ratio > 1.0 && std::isfinite(velocity_rescale_ratio), s,
              "velocity_rescale_ratio", "must be finite and > 1");
  CheckOption(refine_margin >= 0.0 && refine_margin <= 1.0, s, "refine_margin",
              "must be in [0, 1]");
  CheckOption(min_reacquisition_points >= 0, s, "min_reacquisition_points", "must be >= 0");
  CheckOption(max_residual_jump >= 0.0 && std::isfinite(max_residual_jump), s, "max_residual_jump",
              "must be finite and >= 0");
}

Se3Tracker::Se3Tracker(const Se3TrackerOptions& options) : options_(options) { options_.Check(); }

Se3Tracker::LevelEvaluation Se3Tracker::EvaluateLevel(const TrackingReference& reference,
                                                      const Frame& frame, int level,
                                                      const SE3d& T_frame_kf,
                                                      const AffineBrightness& affine) {
  const ReferenceLevel& points = reference.Level(level);
  const PyramidLevel& image = frame.Level(level);
  const LevelCamera camera = ToLevelCamera(frame.Camera(level));
  const Eigen::Matrix3f R = T_frame_kf.RotationMatrix().cast<float>();
  const Eigen::Vector3f t = T_frame_kf.Translation().cast<float>();
  const float gain = affine.Gain(), offset = affine.b;
  const float noise_var = options_.pixel_noise_sigma * options_.pixel_noise_sigma;
  const float k = options_.huber_threshold,
              good_sq = options_.good_threshold * options_.good_threshold;
  const std::size_t num_blocks = (points.Size() + kBlockSize - 1) / kBlockSize;
  block_sums_.assign(num_blocks, LevelEvaluation{});
  const PhotometricModel model{R, t, gain, offset, noise_var, k};
  tbb::parallel_for(std::size_t{0}, num_blocks, [&](std::size_t block) {
    EvaluateBlock(image, camera, model, points, good_sq, block * kBlockSize,
                  std::min(points.Size(), (block + 1) * kBlockSize), &block_sums_[block]);
  });
  LevelEvaluation total;
  for (const LevelEvaluation& block : block_sums_) {  // fixed order: deterministic
    total.equations += block.equations;
    total.in_view += block.in_view;
    total.good += block.good;
    total.sum_sq_residual += block.sum_sq_residual;
    total.sum_gradient_sq += block.sum_gradient_sq;
  }
  return total;
}

double Se3Tracker::Cost(const LevelEvaluation& e, const State& s,
                        const AffineBrightness& prior) const {
  if (e.in_view == 0) return std::numeric_limits<double>::infinity();
  double cost = e.equations.cost / e.in_view;
  if (options_.estimate_affine) {
    const double da = s.affine.a - prior.a, db = s.affine.b - prior.b;
    cost += 0.5 * (options_.affine_prior_a * da * da + options_.affine_prior_b * db * db);
  }
  return cost;
}

int Se3Tracker::OptimizeLevel(const TrackingReference& reference, const Frame& frame, int level,
                              int max_iterations, const AffineBrightness& prior, State* state,
                              LevelEvaluation* final_evaluation) {
  const auto linearize = [&](const State& s) {
    EvaluatedProblem problem;
    problem.evaluation = EvaluateLevel(reference, frame, level, s.T_frame_kf, s.affine);
    const LevelEvaluation& e = problem.evaluation;
    problem.residuals = e.in_view;
    problem.cost = Cost(e, s, prior);
    if (e.in_view == 0) return problem;
    // Per-point normalised normal equations plus the affine prior.
    problem.H = e.equations.SymmetricH() / e.in_view;
    problem.g = e.equations.g / e.in_view;
    if (options_.estimate_affine) {
      problem.H(6, 6) += options_.affine_prior_a;
      problem.H(7, 7) += options_.affine_prior_b;
      problem.g[6] += options_.affine_prior_a * (s.affine.a - prior.a);
      problem.g[7] += options_.affine_prior_b * (s.affine.b - prior.b);
    }
    return problem;
  };
  const auto retract = [](const State& s, const Eigen::Matrix<double, 8, 1>& delta) {
    State next = s;
    next.T_frame_kf = SE3d::Exp(delta.head<6>()) * s.T_frame_kf;
    next.affine.a += static_cast<float>(delta[6]);
    next.affine.b += static_cast<float>(delta[7]);
    return next;
  };
  LmSettings settings;
  settings.max_iterations = max_iterations;
  settings.relative_tolerance = options_.relative_cost_tolerance;
  settings.min_residuals = std::max<int>(
      20,
      static_cast<int>(options_.min_usage * static_cast<double>(reference.Level(level).Size())));
  settings.active = options_.estimate_affine ? 8 : 6;
  EvaluatedProblem final_problem;
  const int iterations =
      MinimizeLevenbergMarquardt<8>(state, linearize, retract, settings, &final_problem);
  *final_evaluation = std::move(final_problem.evaluation);
  return iterations;
}

TrackingResult Se3Tracker::Finish(const TrackingReference& reference, const State& state,
                                  const LevelEvaluation& e) {
  const int level = std::min(options_.finest_level, reference.NumLevels() - 1);
  TrackingResult result;
  result.T_kf_frame = state.T_frame_kf.Inverse();
  result.affine = state.affine;
  TrackingStats& s = result.stats;
  const std::size_t total = reference.Level(level).Size();
  FillPointStatistics({e.in_view, e.good, e.sum_sq_residual, e.sum_gradient_sq}, total, &s);
  const bool finite = result.T_kf_frame.Translation().allFinite() &&
                      std::isfinite(state.affine.a) && std::isfinite(state.affine.b);
  if (!finite || e.in_view < std::max(20.0, options_.min_usage * static_cast<double>(total))) {
    s.diverged = true;
    s.reason = "too few points in view or non-finite estimate";
    result.status = TrackingStatus::kLost;
  } else if (s.mean_gradient_sq < options_.min_mean_gradient_sq) {
    s.reason = "frame has no texture where the keyframe points land";
    result.status = TrackingStatus::kLost;
  } else if (std::abs(state.affine.a) > options_.max_abs_affine_a) {
    s.reason = "brightness gain out of range";
    result.status = TrackingStatus::kLost;
  } else {
    result.status =
        ClassifyConsistency(options_.min_good_ratio_poor, options_.min_good_ratio_ok, &s);
    if (result.status == TrackingStatus::kOk && s.usage < options_.min_usage_ok) {
      s.reason = "little overlap";
      result.status = TrackingStatus::kPoor;
    }
  }
  return result;
}

TrackingResult Se3Tracker::TrackFrom(const TrackingReference& reference, const Frame& frame,
                                     const SE3d& T_kf_frame, const AffineBrightness& affine_guess) {
  return TrackLevels(reference, frame, T_kf_frame, affine_guess, reference.NumLevels() - 1);
}

TrackingResult Se3Tracker::TrackLevels(const TrackingReference& reference, const Frame& frame,
                                       const SE3d& T_kf_frame, const AffineBrightness& affine_guess,
                                       int coarsest) {
  CheckArgument(frame.NumLevels() >= reference.NumLevels(),
                "Se3Tracker: the frame has fewer pyramid levels than the keyframe");
  State state{T_kf_frame.Inverse(), options_.estimate_affine ? affine_guess : AffineBrightness{}};
  const AffineBrightness prior = state.affine;
  const int finest = std::min(options_.finest_level, reference.NumLevels() - 1);
  CheckArgument(reference.FinestLevel() <= finest,
                "Se3Tracker: the reference has no points on the tracker's finest level "
                "(TrackingReferenceOptions::finest_level)");
  std::array<int, kMaxPyramidLevels> iterations{};
  LevelEvaluation finest_evaluation;
  for (int level = std::max(coarsest, finest); level >= finest; --level) {
    iterations[static_cast<std::size_t>(level)] = OptimizeLevel(
        reference, frame, level, MaxIterationsForLevel(options_.max_iterations, level), prior,
        &state, &finest_evaluation);
  }
  TrackingResult result = Finish(reference, state, finest_evaluation);
  result.stats.iterations = iterations;
  return result;
}

TrackingResult Se3Tracker::Refine(const TrackingReference& reference, const Frame& frame,
                                  const SE3d& T_kf_frame, const AffineBrightness& affine_guess) {
  TrackingResult tracked = Track(reference, frame, {T_kf_frame}, affine_guess);
  TrackingResult local = TrackLevels(reference, frame, T_kf_frame, affine_guess, 0);
  local.stats.hypotheses_tried = tracked.stats.hypotheses_tried + 1;
  // Two results of one basin differ by a few points either way; only a clear gain is another.
  return ExplainsMore(local, tracked, options_.refine_margin * tracked.stats.points_in_view)
             ? local
             : tracked;
}

bool Se3Tracker::Confident(const TrackingResult& result) const {
  return result.status == TrackingStatus::kOk &&
         result.stats.good_ratio >= options_.suspect_good_ratio;
}

TrackingResult Se3Tracker::Track(const TrackingReference& reference, const Frame& frame,
                                 const std::vector<SE3d>& hypotheses,
                                 const AffineBrightness& affine_guess) {
  CheckArgument(!hypotheses.empty(), "Se3Tracker::Track: at least one pose hypothesis is needed");
  TrackingResult best = TrackFrom(reference, frame, hypotheses.front(), affine_guess);
  best.stats.hypotheses_tried = 1;
  if (Confident(best)) return best;
  const bool suspect = best.status == TrackingStatus::kOk;  // ok, but not confident
  // Score the alternatives cheaply at the coarsest level.
  std::vector<SE3d> candidates(hypotheses.begin() + 1, hypotheses.end());
  AddRotations(hypotheses.front(), options_.search_rotations_deg, &candidates);
  if (suspect) AddRotations(best.T_kf_frame, options_.search_rotations_deg, &candidates);
  if (best.T_kf_frame.Matrix().allFinite()) {
    // A sudden turn: the first run often finds the rotation but lets the translation slide
    // along the rotation-translation ambiguity; restarted from the motion model's
    // translation it converges to the right basin (docs/math/tracking.md, "A sudden turn").
    candidates.emplace_back(best.T_kf_frame.Rotation(), hypotheses.front().Translation());
  }
  const int coarsest = reference.NumLevels() - 1;
  const AffineBrightness prior = options_.estimate_affine ? affine_guess : AffineBrightness{};
  double best_cost = std::numeric_limits<double>::infinity();
  const SE3d* best_candidate = nullptr;
  for (const SE3d& candidate : candidates) {
    State state{candidate.Inverse(), prior};
    LevelEvaluation e;
    OptimizeLevel(reference, frame, coarsest, options_.hypothesis_iterations, prior, &state, &e);
    const double cost =
        Cost(e, state, prior) /
        std::max(1e-9, e.in_view / static_cast<double>(reference.Level(coarsest).Size()));
    if (cost < best_cost) {
      best_cost = cost;
      best_candidate = &candidate;
    }
  }
  if (best_candidate != nullptr) {
    TrackingResult alternative = TrackFrom(reference, frame, *best_candidate, affine_guess);
    // Of two results with the same status, the one that explains more of the map: the share
    // of consistent points alone prefers a pose that sees fewer of them (docs/math/
    // tracking.md, "Comparing two results").
    if (ExplainsMore(alternative, best, 0.0)) best = alternative;
  }
  best.stats.hypotheses_tried = static_cast<int>(candidates.size()) + 1;
  return best;
}

bool ExplainsMore(const TrackingResult& a, const TrackingResult& b, double margin) {
  return a.status < b.status ||
         (a.status == b.status && a.stats.points_good > b.stats.points_good + margin);
}

void AddRotations(const SE3d& T_kf_frame, const std::vector<double>& angles_deg,
                  std::vector<SE3d>* candidates) {
  for (const double angle : angles_deg) {
    for (int axis = 0; axis < 3; ++axis) {
      for (const double sign : {-1.0, 1.0}) {
        Eigen::Matrix<double, 6, 1> xi = Eigen::Matrix<double, 6, 1>::Zero();
        xi[3 + axis] = sign * angle / kRadToDeg;
        candidates->push_back(T_kf_frame * SE3d::Exp(xi));
      }
    }
  }
}

std::vector<SE3d> MotionHypotheses(const SE3d& T_kf_last, const SE3d& T_prev_last) {
  const SE3d half = SE3d::Exp(0.5 * T_prev_last.Log());
  return {T_kf_last * T_prev_last, T_kf_last * half, T_kf_last * T_prev_last * T_prev_last,
          T_kf_last, SE3d()};
}

}  // namespace parallax
