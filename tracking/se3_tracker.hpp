#pragma once
// Direct SE(3) alignment of a frame to a keyframe (docs/math/tracking.md).

#include <vector>

#include "core/angles.hpp"
#include "core/frame.hpp"
#include "core/normal_equations.hpp"
#include "tracking/tracking_reference.hpp"
#include "tracking/tracking_result.hpp"

namespace parallax {

struct Se3TrackerOptions {
  /// Levels tracked: from the coarsest reference level down to this one. Level 1 (half
  /// resolution) is the default, as in LSD-SLAM: on renders it is within 0.011 deg / 0.02% of
  /// depth at a third of the cost of level 0, which halves those errors (docs/benchmarks.md).
  int finest_level = 1;
  /// Max LM iterations per level (index = level; missing entries use the last). Level 0
  /// starts from a converged level 1, where more than 3 iterations gained nothing measurable.
  std::vector<int> max_iterations = {3, 10, 20, 40, 50};
  /// Image noise sigma_I, grey levels.
  float pixel_noise_sigma = 4.0f;
  /// Huber threshold on the normalised residual r / sigma.
  float huber_threshold = 1.5f;
  /// Estimate the affine brightness (a, b) jointly with the pose.
  bool estimate_affine = true;
  /// Prior weights pulling a and b towards the guess (per point, in normalised units).
  float affine_prior_a = 5.0f;
  float affine_prior_b = 0.01f;
  /// |a| beyond this (a gain outside [0.3, 3.3]) means the fit explains the frame away.
  float max_abs_affine_a = 1.2f;
  /// A point is "good" when |r / sigma| is below this.
  float good_threshold = 3.0f;
  /// Status thresholds on the good ratio.
  float min_good_ratio_ok = 0.6f;
  float min_good_ratio_poor = 0.35f;
  /// Lost when fewer than this fraction of reference points (or 20 points) are in view.
  float min_usage = 0.05f;
  /// Poor when less than this fraction is in view.
  float min_usage_ok = 0.3f;
  /// Lost when the mean |grad I|^2 at warped points is below this (black/flat frame).
  float min_mean_gradient_sq = 4.0f;
  /// Stop a level when the cost decreases by less than this fraction.
  float relative_cost_tolerance = 1e-3f;
  /// LM iterations for each motion hypothesis at the coarsest level.
  int hypothesis_iterations = 5;
  /// An "ok" result with fewer consistent points than this share is suspect: a sudden turn
  /// can leave the constant-velocity start in a wrong basin that still explains most points
  /// (a rendered U-turn's first frame: 62-67% good, 1.5 degrees off; ok frames have
  /// 0.85-0.97). The alternatives are then searched as for a result that is not ok, plus
  /// small rotations around the result itself; the better result wins. 0 disables.
  float suspect_good_ratio = 0.75f;
  /// The search's rotations about each camera axis, degrees, tried around the first motion
  /// hypothesis (and around a suspect result). {1.7, 5.7, 11.5} reaches a turn that starts
  /// between two frames (~12 degrees from the constant-velocity start; the rendered patrols'
  /// U-turns); the default keeps the earlier 0.03 rad alone (docs/math/tracking.md, "Wide
  /// search rotations").
  std::vector<double> search_rotations_deg = {0.03 * kRadToDeg};
  /// The constant-velocity guess (backend/frame_tracker.hpp) is rescaled to the time since
  /// the last tracked frame when that differs from the time the velocity was measured over by
  /// more than this factor either way: frames dropped at a camera's rate (docs/realtime.md),
  /// skipped or lost. Within it (frame-rate jitter; TUM's 32/36 ms) the velocity is used as it
  /// is. Must be > 1.
  double velocity_rescale_ratio = 1.5;
  /// Refine: the pose refined on the finest level alone replaces the coarse-to-fine result
  /// only with more consistent points by this share of the points in view (results in one
  /// basin differ by well under 1%; the stray re-track that motivated Refine, by 16%).
  double refine_margin = 0.05;
  /// A re-acquisition after a loss (FrameTracker::Reacquires) needs at least this many
  /// consistent points besides a confident result: a few hundred points of a smooth wall
  /// match at a wrong pose (docs/math/tracking.md, "Re-acquisition"). 0 disables.
  int min_reacquisition_points = 1000;
  /// A frame tracked with the motion model whose result is not confident and whose residual
  /// rms is above this factor times the last tracked frame's is reported lost
  /// (FrameTracker::AgreesWithHistory): a view explained away at a wrong pose. 0 disables.
  double max_residual_jump = 3.0;

  void Check() const;
};

/// Tracks frames against a TrackingReference by coarse-to-fine Levenberg-Marquardt on
/// T_frame_kf (left increments) and, optionally, affine brightness. The residual is
/// variance-normalised and Huber-weighted; sums run over fixed blocks of points in parallel
/// and are added in block order, so results are deterministic. Not thread-safe (owns scratch
/// buffers); use one tracker per thread.
class Se3Tracker {
 public:
  explicit Se3Tracker(const Se3TrackerOptions& options = {});

  /// Tracks `frame` starting from hypotheses[0] (T_kf_frame guesses, at least one). If that
  /// is not kOk, or kOk but suspect (suspect_good_ratio), the remaining hypotheses, small
  /// rotations around the first (and around a suspect result) and the first result's
  /// rotation with the first hypothesis' translation are scored cheaply at the
  /// coarsest level and the best is tracked fully; the better result wins (status, then
  /// more consistent points).
  TrackingResult Track(const TrackingReference& reference, const Frame& frame,
                       const std::vector<SE3d>& hypotheses,
                       const AffineBrightness& affine_guess = {});

  /// Single coarse-to-fine run from one guess over levels [finest, coarsest].
  TrackingResult TrackFrom(const TrackingReference& reference, const Frame& frame,
                           const SE3d& T_kf_frame, const AffineBrightness& affine_guess);

  /// Tracks again a frame whose pose T_kf_frame is already close (the map it was tracked on
  /// has been refined since): Track from it, and the guess refined on the finest tracked
  /// level alone; the better of the two wins (status, then clearly more consistent points:
  /// refine_margin). The
  /// coarse levels can pull a converged pose into another basin (docs/math/tracking.md,
  /// "Tracking a frame again").
  TrackingResult Refine(const TrackingReference& reference, const Frame& frame,
                        const SE3d& T_kf_frame, const AffineBrightness& affine_guess);

  /// "ok" and not suspect: at least `suspect_good_ratio` of the points consistent. Track
  /// searches on from any other result; a re-acquisition after a loss needs one
  /// (FrameTracker::Reacquires).
  bool Confident(const TrackingResult& result) const;

  const Se3TrackerOptions& Options() const { return options_; }

  /// Normal equations (6 pose + 2 affine parameters, per-point normalised, without prior)
  /// and statistics of `level` at a state. Exposed for tests and the Sim(3) tracker's
  /// reuse of the kernel.
  struct LevelEvaluation {
    NormalEquations<8> equations;
    int in_view = 0;
    int good = 0;
    double sum_sq_residual = 0.0;
    double sum_gradient_sq = 0.0;
  };
  LevelEvaluation EvaluateLevel(const TrackingReference& reference, const Frame& frame, int level,
                                const SE3d& T_frame_kf, const AffineBrightness& affine);

 private:
  struct State {
    SE3d T_frame_kf;
    AffineBrightness affine;
  };
  double Cost(const LevelEvaluation& e, const State& s, const AffineBrightness& prior) const;
  /// One coarse-to-fine run from one guess over levels [finest, max(coarsest, finest)]
  /// (TrackFrom: every level; Refine: the finest alone).
  TrackingResult TrackLevels(const TrackingReference& reference, const Frame& frame,
                             const SE3d& T_kf_frame, const AffineBrightness& affine_guess,
                             int coarsest);
  /// Optimises `state` on `level`; `final_evaluation` receives the level's evaluation at the
  /// returned state.
  int OptimizeLevel(const TrackingReference& reference, const Frame& frame, int level,
                    int max_iterations, const AffineBrightness& prior, State* state,
                    LevelEvaluation* final_evaluation);
  /// The result at `state` from `e`, its evaluation on the finest tracked level.
  TrackingResult Finish(const TrackingReference& reference, const State& state,
                        const LevelEvaluation& e);

  Se3TrackerOptions options_;
  std::vector<LevelEvaluation> block_sums_;  // scratch, one per block of points
};

/// Motion hypotheses for the next frame from the last tracked pose and the last inter-frame
/// motion T_prev_last (pose of the last frame in the previous one): constant velocity, half
/// and double velocity, zero motion, and the keyframe pose itself.
std::vector<SE3d> MotionHypotheses(const SE3d& T_kf_last, const SE3d& T_prev_last);
/// Of two results, whether `a` explains more of the map than `b`: a better status, or the
/// same with more than `margin` more consistent points (docs/math/tracking.md, "Comparing two
/// results").
bool ExplainsMore(const TrackingResult& a, const TrackingResult& b, double margin);
/// Appends, for each angle (degrees), the six poses turned by +-angle about each camera axis.
void AddRotations(const SE3d& T_kf_frame, const std::vector<double>& angles_deg,
                  std::vector<SE3d>* candidates);

}  // namespace parallax
