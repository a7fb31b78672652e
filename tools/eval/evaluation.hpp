#pragma once
// Trajectory accuracy metrics: ATE, RPE and KITTI segment errors
// (definitions: docs/evaluation.md).

#include <string>
#include <vector>

#include "tools/dataset/trajectory.hpp"
#include "tools/eval/alignment.hpp"

namespace parallax {

struct EvaluationOptions {
  AlignmentMode alignment = AlignmentMode::kSim3;
  /// Association window, seconds (TUM tools' default 0.02).
  double max_dt = 0.02;
  /// Time step of the per-second RPE, seconds.
  double rpe_delta_seconds = 1.0;
  /// Path length step of the per-distance RPE (ground-truth units); 0: a tenth of the
  /// matched ground-truth path.
  double rpe_delta_meters = 0.0;
  /// Timestamps of the sequence's images: when given, `coverage` is the share of image frames
  /// with an estimated pose (a ground truth at 100 Hz or one that misses frames does not
  /// change it); otherwise matched / ground-truth poses in the estimate's span.
  std::vector<double> frame_timestamps;

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// Summary of a set of non-negative errors. All zero when count == 0.
struct ErrorStatistics {
  std::size_t count = 0;
  double rmse = 0.0;
  double mean = 0.0;
  double median = 0.0;
  double max = 0.0;
};
ErrorStatistics ComputeStatistics(std::vector<double> errors);

struct RelativePoseError {
  ErrorStatistics translation;  ///< trajectory units (metres for ground truth in metres)
  ErrorStatistics rotation_deg;
};

/// Monocular scale drift along the path: for pose pairs rpe_delta_meters of ground-truth path
/// apart, ratio = |estimated displacement| / |ground-truth displacement| after alignment, so a
/// trajectory without scale drift has every ratio near 1 under sim3 alignment
/// (docs/evaluation.md).
struct LocalScaleStatistics {
  std::size_t count = 0;
  double min_ratio = 0.0;
  double max_ratio = 0.0;
  double log_rmse = 0.0;  ///< rms of ln(ratio)
};

/// Average of KITTI's drift over one segment length (e.g. 100 m).
struct KittiSegmentError {
  double length = 0.0;
  std::size_t segments = 0;
  double translation_percent = 0.0;    ///< mean |t_err| / length * 100
  double rotation_deg_per_100m = 0.0;  ///< mean angle / length * 100, degrees
};

struct EvaluationReport {
  AlignmentMode alignment = AlignmentMode::kSim3;
  std::size_t estimate_poses = 0;
  std::size_t groundtruth_poses = 0;
  std::size_t matched = 0;
  /// Ground-truth poses whose time lies inside the estimate's [first, last] span.
  std::size_t groundtruth_in_span = 0;
  double coverage = 0.0;                 ///< see EvaluationOptions::frame_timestamps
  std::size_t frames = 0;                ///< image frames (0: not known)
  std::size_t frames_with_pose = 0;      ///< image frames with an estimated pose
  Sim3d S_gt_est;                        ///< alignment applied to the estimate
  ErrorStatistics ate;                   ///< absolute trajectory error of positions after alignment
  double ate_max_timestamp = 0.0;        ///< the estimate's pose with the largest ATE (ate.max)
  double groundtruth_path_length = 0.0;  ///< along the matched ground-truth poses
  double ate_rmse_percent_of_path = 0.0;
  double ate_max_percent_of_path = 0.0;  ///< the worst pose's error (issue 15's per-frame bound)
  RelativePoseError rpe_per_frame;       ///< consecutive matched poses
  RelativePoseError rpe_per_second;      ///< pairs rpe_delta_seconds apart
  double rpe_delta_meters = 0.0;         ///< the step actually used
  RelativePoseError rpe_per_distance;    ///< pairs rpe_delta_meters of ground-truth path apart
  LocalScaleStatistics local_scale;      ///< over the same pairs as rpe_per_distance
  std::vector<KittiSegmentError> kitti;  ///< lengths 100..800 m that fit in the path
};

/// Associates, aligns and measures. Throws std::invalid_argument when fewer than 3 poses
/// associate (naming max_dt) or the alignment is degenerate.
EvaluationReport Evaluate(const Trajectory& estimate, const Trajectory& groundtruth,
                          const EvaluationOptions& options);

/// Compact human-readable table.
std::string FormatReport(const EvaluationReport& report);
/// Machine-readable JSON (keys documented in docs/evaluation.md).
std::string ReportToJson(const EvaluationReport& report);

}  // namespace parallax
