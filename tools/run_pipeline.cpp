#include "tools/run_pipeline.hpp"

#include <fmt/format.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "core/check.hpp"
#include "core/undistorter.hpp"
#include "tools/dataset/frame_prefetcher.hpp"
#include "tools/dataset/input_error.hpp"
#include "tools/dataset/trajectory.hpp"

namespace parallax {
namespace {

double Percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  return values[static_cast<std::size_t>(std::lround(q * static_cast<double>(values.size() - 1)))];
}

/// Streams the map (two passes: count, then write): millions of points are never copied.
std::size_t WritePly(const std::string& path, const System& system) {
  std::size_t count = 0;
  system.ForEachMapPoint([&](const Eigen::Vector3f&) { ++count; });
  std::ofstream out(path);
  if (!out) throw InputError(path, "cannot open for writing");
  out << "ply\nformat ascii 1.0\nelement vertex " << count
      << "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  system.ForEachMapPoint([&](const Eigen::Vector3f& p) {
    out << fmt::format("{:.5f} {:.5f} {:.5f}\n", p.x(), p.y(), p.z());
  });
  if (!out) throw InputError(path, "write failed");
  return count;
}

void WriteStats(const std::string& path, const RunSummary& s) {
  const nlohmann::json j = {
      {"frames", s.frames},
      {"frames_tracked", s.frames_tracked},
      {"frames_unusable", s.frames_unusable},
      {"outcome", s.Outcome()},
      {"keyframes", s.keyframes},
      {"loop_closures", s.edges.loop},
      {"keyframe_graph",
       {{"edges",
         {{"odometry", s.edges.odometry},
          {"neighbour", s.edges.neighbour},
          {"loop", s.edges.loop}}},
        {"alignments", s.alignments},
        {"alignments_rejected", s.alignments_rejected},
        {"optimisations", s.optimisations},
        {"optimisation_iterations", s.optimisation_iterations},
        {"optimisation_ms", {{"p50", s.optimisation_ms_p50}, {"p95", s.optimisation_ms_p95}}},
        {"bytes", s.graph_bytes},
        {"bytes_per_keyframe",
         s.keyframes > 0 ? s.graph_bytes / static_cast<std::size_t>(s.keyframes) : 0}}},
      {"relocalisations", 0},
      {"initialised_at_frame", s.initialised_at_frame},
      {"wall_s", s.wall_s},
      {"fps", s.fps},
      {"tracking_ms", {{"p50", s.tracking_ms_p50}, {"p95", s.tracking_ms_p95}}},
      {"mapping_ms", {{"p50", s.mapping_ms_p50}, {"p95", s.mapping_ms_p95}}},
      {"map_points", s.map_points},
      {"peak_rss_mb", s.peak_rss_mb}};
  std::ofstream out(path);
  if (!out) throw InputError(path, "cannot open for writing");
  out << j.dump(2) << "\n";
}

std::string EventNames(const std::vector<SystemEvent>& events) {
  std::string names;
  for (const SystemEvent& e : events) {
    if (!names.empty()) names += ';';
    switch (e.kind) {
      case SystemEvent::Kind::kKeyframeCreated:
        names += "keyframe";
        break;
      case SystemEvent::Kind::kKeyframeFinished:
        names += "finished";
        break;
      case SystemEvent::Kind::kGraphOptimised:
        names += "optimised";
        break;
      case SystemEvent::Kind::kLost:
        names += "lost";
        break;
      case SystemEvent::Kind::kRecovered:
        names += "recovered";
        break;
      case SystemEvent::Kind::kPosesRevised:
        names += "revised";
        break;
      case SystemEvent::Kind::kRestarted:
        names += "restarted";
        break;
    }
  }
  return names;
}

void WriteTrajectory(const std::filesystem::path& out, const std::string& name,
                     const Trajectory& trajectory, RunOptions::TrajectoryFormat format) {
  const std::string path = (out / (name + ".txt")).string();
  if (format == RunOptions::TrajectoryFormat::kTum) {
    WriteTumTrajectory(path, trajectory);
    return;
  }
  WriteKittiTrajectory(path, trajectory);
  std::ofstream times((out / (name + ".times.txt")).string());
  for (const StampedPose& p : trajectory) times << FormatTimestamp(p.timestamp) << '\n';
  if (!times) throw InputError((out / (name + ".times.txt")).string(), "write failed");
}

}  // namespace

std::string RunSummary::Outcome() const {
  if (frames_tracked == 0) return "tracked_nothing";
  return 2 * frames_tracked >= frames ? "tracked" : "tracked_partially";
}

RunSummary RunDataset(const RunOptions& options) {
  CheckArgument(options.max_frames >= 0, "--max-frames must be >= 0");
  const auto reader = OpenDataset(options.dataset, options.dataset_options);
  const Undistorter undistorter(reader->GetCamera(), reader->SuggestedRectification());
  System system(undistorter.OutputCamera(), options.system);
  std::error_code ec;
  std::filesystem::create_directories(options.out_dir, ec);
  if (!std::filesystem::is_directory(options.out_dir)) {
    throw InputError(options.out_dir, "cannot create the output folder");
  }
  Trajectory online;  // the poses as reported when each frame was processed
  std::vector<double> tracking_ms, mapping_ms;
  RunSummary summary;
  const auto start = std::chrono::steady_clock::now();
  const std::size_t num_frames = reader->NumFrames();  // the reader belongs to `frames` now
  FramePrefetcher frames(reader.get(), &undistorter);
  const std::string frame_log_path =
      (std::filesystem::path(options.out_dir) / "frames.csv").string();
  std::ofstream frame_log(frame_log_path);
  if (!frame_log) throw InputError(frame_log_path, "cannot open for writing");
  frame_log << "frame,timestamp,status,posed,keyframe,tracking_ms,mapping_ms,events\n";
  while (options.max_frames == 0 || summary.frames < options.max_frames) {
    const auto frame = frames.Next();
    if (!frame) break;
    const FrameResult result = system.ProcessFrame(frame->image, frame->timestamp);
    ++summary.frames;
    summary.frames_tracked += result.T_w_c.has_value();
    if (result.T_w_c) online.push_back(StampedPose{frame->timestamp, *result.T_w_c});
    frame_log << fmt::format("{},{},{},{},{},{:.3f},{:.3f},{}\n", summary.frames - 1,
                             FormatTimestamp(frame->timestamp), ToString(result.status),
                             result.T_w_c ? 1 : 0, result.is_keyframe ? 1 : 0, result.tracking_ms,
                             result.mapping_ms, EventNames(result.events));
    tracking_ms.push_back(result.tracking_ms);
    mapping_ms.push_back(result.mapping_ms);
    if (options.progress) {
      std::fprintf(stderr, "\rframe %d/%zu  tracked %d  keyframes %zu  %s   ", summary.frames,
                   num_frames, summary.frames_tracked, system.Keyframes().size(),
                   ToString(result.status).c_str());
    }
  }
  if (options.progress) std::fprintf(stderr, "\n");
  if (summary.frames == 0) throw InputError(options.dataset, "has no frames");
  Trajectory trajectory;
  for (const FramePose& pose : system.Trajectory()) {
    trajectory.push_back({pose.timestamp, pose.T_w_c});
  }
  summary.frames_tracked = static_cast<int>(trajectory.size());
  summary.initialised_at_frame = system.InitialisedAtFrame();
  summary.frames_unusable = system.FramesUnusable();
  summary.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  summary.fps = summary.frames / std::max(summary.wall_s, 1e-9);
  summary.keyframes = static_cast<int>(system.Keyframes().size());
  summary.tracking_ms_p50 = Percentile(tracking_ms, 0.5);
  summary.tracking_ms_p95 = Percentile(tracking_ms, 0.95);
  summary.mapping_ms_p50 = Percentile(mapping_ms, 0.5);
  summary.mapping_ms_p95 = Percentile(mapping_ms, 0.95);
  summary.edges = system.Graph().CountEdges();
  summary.optimisations = system.Backend().optimisations;
  summary.optimisation_iterations = system.Backend().iterations;
  summary.alignments = system.Backend().alignments;
  summary.alignments_rejected = system.Backend().edges_rejected;
  summary.optimisation_ms_p50 = Percentile(system.Backend().optimisation_ms, 0.5);
  summary.optimisation_ms_p95 = Percentile(system.Backend().optimisation_ms, 0.95);
  summary.graph_bytes = system.Graph().Bytes();
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  summary.peak_rss_mb = static_cast<double>(usage.ru_maxrss) / 1024.0;
  const std::filesystem::path out(options.out_dir);
  WriteTrajectory(out, "trajectory", trajectory, options.trajectory_format);
  WriteTrajectory(out, "trajectory_online", online, options.trajectory_format);
  if (!frame_log.flush()) throw InputError(frame_log_path, "write failed");
  Trajectory keyframes;
  for (const KeyframeRecord& kf : system.Keyframes()) {
    keyframes.push_back({kf.timestamp, SE3d(kf.S_w_kf.Rotation(), kf.S_w_kf.Translation())});
  }
  WriteTumTrajectory((out / "keyframes.txt").string(), keyframes);
  summary.map_points = WritePly((out / "map.ply").string(), system);
  WriteStats((out / "stats.json").string(), summary);
  return summary;
}

}  // namespace parallax
