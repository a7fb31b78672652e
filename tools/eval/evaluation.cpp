#include "tools/eval/evaluation.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>

#include "core/check.hpp"
#include "tools/eval/association.hpp"

namespace parallax {
namespace {

double RotationAngleDeg(const SO3d& R) { return R.Log().norm() * 180.0 / std::numbers::pi; }

// The estimate after alignment: positions mapped by S, rotations by S's rotation only.
SE3d ApplyAlignment(const Sim3d& S, const SE3d& T) {
  return SE3d(S.Rotation() * T.Rotation(), S * T.Translation());
}

RelativePoseError ComputeRpe(const std::vector<SE3d>& est, const std::vector<SE3d>& gt,
                             const std::vector<std::pair<std::size_t, std::size_t>>& pairs) {
  std::vector<double> translation, rotation;
  for (const auto& [i, j] : pairs) {
    const SE3d error = (gt[i].Inverse() * gt[j]).Inverse() * (est[i].Inverse() * est[j]);
    translation.push_back(error.Translation().norm());
    rotation.push_back(RotationAngleDeg(error.Rotation()));
  }
  return {ComputeStatistics(translation), ComputeStatistics(rotation)};
}

LocalScaleStatistics ComputeLocalScale(
    const std::vector<SE3d>& est, const std::vector<SE3d>& gt,
    const std::vector<std::pair<std::size_t, std::size_t>>& pairs) {
  LocalScaleStatistics stats;
  double sum_log_sq = 0.0;
  for (const auto& [i, j] : pairs) {
    const double gt_length = (gt[j].Translation() - gt[i].Translation()).norm();
    if (!(gt_length > 0.0)) continue;
    const double ratio = (est[j].Translation() - est[i].Translation()).norm() / gt_length;
    stats.min_ratio = stats.count ? std::min(stats.min_ratio, ratio) : ratio;
    stats.max_ratio = stats.count ? std::max(stats.max_ratio, ratio) : ratio;
    const double log_ratio = ratio > 0.0 ? std::log(ratio) : 0.0;
    sum_log_sq += log_ratio * log_ratio;
    ++stats.count;
  }
  if (stats.count) stats.log_rmse = std::sqrt(sum_log_sq / static_cast<double>(stats.count));
  return stats;
}

std::vector<KittiSegmentError> ComputeKittiErrors(const std::vector<SE3d>& est,
                                                  const std::vector<SE3d>& gt) {
  std::vector<double> distance(gt.size(), 0.0);
  for (std::size_t i = 1; i < gt.size(); ++i) {
    distance[i] = distance[i - 1] + (gt[i].Translation() - gt[i - 1].Translation()).norm();
  }
  std::vector<KittiSegmentError> out;
  for (int len = 100; len <= 800; len += 100) {
    KittiSegmentError segment{static_cast<double>(len), 0, 0.0, 0.0};
    for (std::size_t first = 0; first < gt.size(); first += 10) {
      const auto last_it = std::lower_bound(distance.begin() + static_cast<std::ptrdiff_t>(first),
                                            distance.end(), distance[first] + len);
      if (last_it == distance.end()) break;
      const auto last = static_cast<std::size_t>(last_it - distance.begin());
      const SE3d error =
          (est[first].Inverse() * est[last]).Inverse() * (gt[first].Inverse() * gt[last]);
      segment.translation_percent += error.Translation().norm() / len * 100.0;
      segment.rotation_deg_per_100m += RotationAngleDeg(error.Rotation()) / len * 100.0;
      ++segment.segments;
    }
    if (segment.segments == 0) break;
    segment.translation_percent /= static_cast<double>(segment.segments);
    segment.rotation_deg_per_100m /= static_cast<double>(segment.segments);
    out.push_back(segment);
  }
  return out;
}

}  // namespace

void EvaluationOptions::Check() const {
  CheckOption(std::isfinite(max_dt) && max_dt > 0.0, "EvaluationOptions", "max_dt", "must be > 0");
  CheckOption(std::isfinite(rpe_delta_seconds) && rpe_delta_seconds > 0.0, "EvaluationOptions",
              "rpe_delta_seconds", "must be > 0");
  CheckOption(std::isfinite(rpe_delta_meters) && rpe_delta_meters >= 0.0, "EvaluationOptions",
              "rpe_delta_meters", "must be >= 0");
}

ErrorStatistics ComputeStatistics(std::vector<double> errors) {
  ErrorStatistics s;
  s.count = errors.size();
  if (errors.empty()) return s;
  double sum = 0.0, sum_sq = 0.0;
  for (const double e : errors) {
    sum += e;
    sum_sq += e * e;
    s.max = std::max(s.max, e);
  }
  const auto n = static_cast<double>(errors.size());
  s.mean = sum / n;
  s.rmse = std::sqrt(sum_sq / n);
  std::sort(errors.begin(), errors.end());
  const std::size_t mid = errors.size() / 2;
  s.median = errors.size() % 2 ? errors[mid] : 0.5 * (errors[mid - 1] + errors[mid]);
  return s;
}

EvaluationReport Evaluate(const Trajectory& estimate, const Trajectory& groundtruth,
                          const EvaluationOptions& options) {
  options.Check();
  EvaluationReport report;
  report.alignment = options.alignment;
  report.estimate_poses = estimate.size();
  report.groundtruth_poses = groundtruth.size();
  const auto pairs = AssociateByTimestamp(estimate, groundtruth, options.max_dt);
  report.matched = pairs.size();
  if (pairs.size() < 3) {
    throw std::invalid_argument(fmt::format(
        "only {} pose(s) associate within max_dt = {} s (need at least 3); check that both "
        "files use the same time base",
        pairs.size(), options.max_dt));
  }
  if (!estimate.empty()) {
    for (const StampedPose& p : groundtruth) {
      report.groundtruth_in_span += p.timestamp >= estimate.front().timestamp - options.max_dt &&
                                    p.timestamp <= estimate.back().timestamp + options.max_dt;
    }
  }
  report.coverage = static_cast<double>(report.matched) /
                    static_cast<double>(std::max<std::size_t>(report.groundtruth_in_span, 1));
  if (!options.frame_timestamps.empty()) {
    report.frames = options.frame_timestamps.size();
    Trajectory frames;
    for (const double t : options.frame_timestamps) frames.push_back({t, SE3d()});
    report.frames_with_pose = AssociateByTimestamp(estimate, frames, options.max_dt).size();
    report.coverage =
        static_cast<double>(report.frames_with_pose) / static_cast<double>(report.frames);
  }
  std::vector<Eigen::Vector3d> x, y;
  std::vector<SO3d> R_x, R_y;  // settle the turn about the line of a straight trajectory
  for (const auto& p : pairs) {
    x.push_back(estimate[p.estimate_index].T_w_c.Translation());
    y.push_back(groundtruth[p.groundtruth_index].T_w_c.Translation());
    R_x.push_back(estimate[p.estimate_index].T_w_c.Rotation());
    R_y.push_back(groundtruth[p.groundtruth_index].T_w_c.Rotation());
  }
  report.S_gt_est = AlignUmeyama(x, y, options.alignment, R_x, R_y);
  std::vector<double> ate;
  std::vector<SE3d> est, gt;
  std::vector<double> times;
  for (const auto& p : pairs) {
    est.push_back(ApplyAlignment(report.S_gt_est, estimate[p.estimate_index].T_w_c));
    gt.push_back(groundtruth[p.groundtruth_index].T_w_c);
    times.push_back(estimate[p.estimate_index].timestamp);
    ate.push_back((est.back().Translation() - gt.back().Translation()).norm());
    if (gt.size() > 1) {
      report.groundtruth_path_length +=
          (gt.back().Translation() - gt[gt.size() - 2].Translation()).norm();
    }
  }
  report.ate = ComputeStatistics(ate);
  report.ate_max_timestamp =
      times[static_cast<std::size_t>(std::max_element(ate.begin(), ate.end()) - ate.begin())];
  if (report.groundtruth_path_length > 0.0) {
    report.ate_rmse_percent_of_path = report.ate.rmse / report.groundtruth_path_length * 100.0;
    report.ate_max_percent_of_path = report.ate.max / report.groundtruth_path_length * 100.0;
  }
  std::vector<std::pair<std::size_t, std::size_t>> per_frame, per_second;
  for (std::size_t i = 0; i + 1 < est.size(); ++i) per_frame.emplace_back(i, i + 1);
  for (std::size_t i = 0, j = 0; i < est.size(); ++i) {
    j = std::max(j, i + 1);
    while (j < est.size() && times[j] - times[i] < options.rpe_delta_seconds) ++j;
    if (j >= est.size()) break;
    per_second.emplace_back(i, j);
  }
  report.rpe_per_frame = ComputeRpe(est, gt, per_frame);
  report.rpe_per_second = ComputeRpe(est, gt, per_second);
  report.rpe_delta_meters = options.rpe_delta_meters > 0.0 ? options.rpe_delta_meters
                                                           : report.groundtruth_path_length / 10.0;
  if (report.rpe_delta_meters > 0.0) {
    std::vector<double> along(gt.size(), 0.0);
    for (std::size_t i = 1; i < gt.size(); ++i) {
      along[i] = along[i - 1] + (gt[i].Translation() - gt[i - 1].Translation()).norm();
    }
    std::vector<std::pair<std::size_t, std::size_t>> per_distance;
    for (std::size_t i = 0, j = 0; i < est.size(); ++i) {
      j = std::max(j, i + 1);
      while (j < est.size() && along[j] - along[i] < report.rpe_delta_meters) ++j;
      if (j >= est.size()) break;
      per_distance.emplace_back(i, j);
    }
    report.rpe_per_distance = ComputeRpe(est, gt, per_distance);
    report.local_scale = ComputeLocalScale(est, gt, per_distance);
  }
  report.kitti = ComputeKittiErrors(est, gt);
  return report;
}

std::string FormatReport(const EvaluationReport& r) {
  std::string s;
  s += fmt::format("poses        estimate {}  ground truth {}  matched {}  coverage {:.1f}%\n",
                   r.estimate_poses, r.groundtruth_poses, r.matched, 100.0 * r.coverage);
  s += fmt::format("alignment    {} (scale {:.6f})\n", ToString(r.alignment), r.S_gt_est.Scale());
  s += fmt::format("ATE          rmse {:.6f}  mean {:.6f}  median {:.6f}  max {:.6f}\n", r.ate.rmse,
                   r.ate.mean, r.ate.median, r.ate.max);
  s += fmt::format("path         {:.4f} (ground truth); ATE rmse = {:.3f}% of path\n",
                   r.groundtruth_path_length, r.ate_rmse_percent_of_path);
  s += fmt::format("worst pose   t = {}: {:.6f} = {:.3f}% of path\n", r.ate_max_timestamp,
                   r.ate.max, r.ate_max_percent_of_path);
  const auto rpe = [&](const char* name, const RelativePoseError& e) {
    s += fmt::format("{} trans rmse {:.6f} mean {:.6f}  rot rmse {:.4f} deg  ({} pairs)\n", name,
                     e.translation.rmse, e.translation.mean, e.rotation_deg.rmse,
                     e.translation.count);
  };
  rpe("RPE/frame   ", r.rpe_per_frame);
  rpe("RPE/second  ", r.rpe_per_second);
  rpe(fmt::format("RPE/{:.3g} m", r.rpe_delta_meters).c_str(), r.rpe_per_distance);
  if (r.local_scale.count > 0) {
    s += fmt::format("scale/{:.3g} m local scale {:.3f} .. {:.3f}  rms |ln| {:.4f}  ({} pairs)\n",
                     r.rpe_delta_meters, r.local_scale.min_ratio, r.local_scale.max_ratio,
                     r.local_scale.log_rmse, r.local_scale.count);
  }
  if (r.frames > 0) {
    s += fmt::format("frames       {} of {} image frames have a pose\n", r.frames_with_pose,
                     r.frames);
  }
  if (r.kitti.empty()) {
    s += "KITTI        path shorter than 100: no segment errors\n";
  }
  for (const KittiSegmentError& k : r.kitti) {
    s += fmt::format("KITTI {:4.0f}   t {:.3f}%  r {:.4f} deg/100  ({} segments)\n", k.length,
                     k.translation_percent, k.rotation_deg_per_100m, k.segments);
  }
  return s;
}

std::string ReportToJson(const EvaluationReport& r) {
  const auto stats = [](const ErrorStatistics& e) {
    return nlohmann::json{{"count", e.count},
                          {"rmse", e.rmse},
                          {"mean", e.mean},
                          {"median", e.median},
                          {"max", e.max}};
  };
  nlohmann::json kitti = nlohmann::json::array();
  for (const KittiSegmentError& k : r.kitti) {
    kitti.push_back({{"length", k.length},
                     {"segments", k.segments},
                     {"translation_percent", k.translation_percent},
                     {"rotation_deg_per_100m", k.rotation_deg_per_100m}});
  }
  const nlohmann::json j = {{"alignment", ToString(r.alignment)},
                            {"scale", r.S_gt_est.Scale()},
                            {"estimate_poses", r.estimate_poses},
                            {"groundtruth_poses", r.groundtruth_poses},
                            {"matched", r.matched},
                            {"groundtruth_in_span", r.groundtruth_in_span},
                            {"coverage", r.coverage},
                            {"coverage_of", r.frames > 0 ? "image frames" : "ground truth"},
                            {"frames", r.frames},
                            {"frames_with_pose", r.frames_with_pose},
                            {"ate", stats(r.ate)},
                            {"groundtruth_path_length", r.groundtruth_path_length},
                            {"ate_rmse_percent_of_path", r.ate_rmse_percent_of_path},
                            {"ate_max_timestamp", r.ate_max_timestamp},
                            {"ate_max_percent_of_path", r.ate_max_percent_of_path},
                            {"rpe_per_frame",
                             {{"translation", stats(r.rpe_per_frame.translation)},
                              {"rotation_deg", stats(r.rpe_per_frame.rotation_deg)}}},
                            {"rpe_per_second",
                             {{"translation", stats(r.rpe_per_second.translation)},
                              {"rotation_deg", stats(r.rpe_per_second.rotation_deg)}}},
                            {"rpe_per_distance",
                             {{"delta", r.rpe_delta_meters},
                              {"translation", stats(r.rpe_per_distance.translation)},
                              {"rotation_deg", stats(r.rpe_per_distance.rotation_deg)}}},
                            {"local_scale",
                             {{"count", r.local_scale.count},
                              {"min_ratio", r.local_scale.min_ratio},
                              {"max_ratio", r.local_scale.max_ratio},
                              {"log_rmse", r.local_scale.log_rmse}}},
                            {"kitti_segments", kitti}};
  return j.dump(2);
}

}  // namespace parallax
