#include "tools/run_outputs.hpp"

#include <fmt/format.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <vector>

#include "tools/dataset/input_error.hpp"

namespace fs = std::filesystem;

namespace parallax {
namespace {

/// Every file a run writes; an earlier run's are removed first so none looks current.
const std::vector<std::string>& OutputNames() {
  static const std::vector<std::string> names = {"run.json",
                                                 "frames.csv",
                                                 "trajectory.txt",
                                                 "trajectory.times.txt",
                                                 "trajectory_online.txt",
                                                 "trajectory_online.times.txt",
                                                 "keyframes.txt",
                                                 "map.ply",
                                                 "stats.json"};
  return names;
}

/// Writes through `write(path)` to a temporary file and renames it into place.
template <typename Write>
void WriteAtomically(const std::string& path, Write write) {
  const std::string partial = path + ".partial";
  write(partial);
  std::error_code ec;
  fs::rename(partial, path, ec);
  if (ec) throw InputError(path, "cannot replace: " + ec.message());
}

/// Streams the map (two passes: count, then write): millions of points are never copied.
std::size_t WritePly(const std::string& path, const System& system) {
  std::size_t count = 0;
  system.ForEachMapPoint([&](const MapPoint&) { ++count; });
  std::ofstream out(path, std::ios::binary);
  if (!out) throw InputError(path, "cannot open for writing");
  // Binary (15 bytes a point; ASCII took about 30 and seconds to write for millions of
  // points); the grey level as equal red, green and blue, which every viewer shows.
  out << "ply\nformat binary_little_endian 1.0\nelement vertex " << count
      << "\nproperty float x\nproperty float y\nproperty float z\n"
         "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
  static_assert(std::endian::native == std::endian::little, "PLY is written little-endian");
  // Records are gathered in blocks: a stream write per 15-byte record took 0.3 s for the TUM
  // clip's 460k points.
  constexpr std::size_t kRecord = 15, kBlockRecords = 1 << 14;
  std::vector<char> block(kRecord * kBlockRecords);
  std::size_t used = 0;
  system.ForEachMapPoint([&](const MapPoint& p) {
    std::memcpy(block.data() + used, p.p_w.data(), 12);
    std::memset(block.data() + used + 12, p.intensity, 3);
    used += kRecord;
    if (used == block.size()) {
      out.write(block.data(), static_cast<std::streamsize>(used));
      used = 0;
    }
  });
  out.write(block.data(), static_cast<std::streamsize>(used));
  if (!out) throw InputError(path, "write failed");
  return count;
}

void WriteStats(const std::string& path, const RunSummary& s) {
  const nlohmann::json j = {
      {"frames", s.frames},
      {"frames_tracked", s.frames_tracked},
      {"frames_unusable", s.frames_unusable},
      {"frames_unreadable", s.frames_unreadable},
      {"outcome", s.Outcome()},
      {"status", s.status},
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
      {"place_recognition",
       {{"loop_candidates", s.loop_candidates},
        {"loops_verified", s.loop_checks},
        {"loops_rejected", s.loops_rejected},
        {"loops_closed", s.loops_closed},
        {"ms_per_keyframe", {{"p50", s.loop_ms_p50}, {"p95", s.loop_ms_p95}}},
        {"bytes", s.place_bytes}}},
      {"relocalisations", s.relocalisations},
      {"relocalisation_attempts", s.relocalisation_attempts},
      {"maps", s.maps},
      {"maps_started", s.maps_started},
      {"merges", s.merges},
      {"divergences",
       {{"frames", s.frames_diverged},
        {"depth_estimates", s.depth_estimates_diverged},
        {"keyframes", s.keyframes_diverged},
        {"backend_steps", s.backend_steps_diverged}}},
      {"initialised_at_frame", s.initialised_at_frame},
      {"wall_s", s.wall_s},
      {"fps", s.fps},
      {"tracking_ms", {{"p50", s.tracking_ms_p50}, {"p95", s.tracking_ms_p95}}},
      {"mapping_ms", {{"p50", s.mapping_ms_p50}, {"p95", s.mapping_ms_p95}}},
      {"latency_ms",
       {{"p50", s.latency_ms_p50}, {"p95", s.latency_ms_p95}, {"max", s.latency_ms_max}}},
      {"tracked_latency_ms",
       {{"p50", s.tracked_latency_ms_p50},
        {"p95", s.tracked_latency_ms_p95},
        {"max", s.tracked_latency_ms_max}}},
      {"map_points", s.map_points},
      {"peak_rss_mb", s.peak_rss_mb},
      {"heap_huge_pages", s.heap_huge_pages},
      {"photometric_correction", s.photometric},
      {"end_of_input_events", s.end_events}};
  nlohmann::json all = j;
  if (s.realtime) {
    all["realtime"] = {{"rate", s.rate},
                       {"frames_dropped", s.frames_dropped},
                       {"frames_tracked_live", s.mapping.frames_tracked_live},
                       {"frames_waiting_for_mapping", s.mapping.frames_mapped_waiting},
                       {"frames_queued_for_start", s.mapping.frames_queued_for_start},
                       {"frames_waiting_for_keyframe", s.mapping.frames_waiting_for_keyframe},
                       {"frames_paced_for_keyframe", s.mapping.frames_paced_for_keyframe},
                       {"frames_tracked_on_bridge", s.mapping.frames_tracked_on_bridge},
                       {"frames_skipped_by_mapping", s.mapping.frames_skipped_by_mapping},
                       {"shutdown_ms", s.shutdown_ms}};
  }
  std::ofstream out(path);
  if (!out) throw InputError(path, "cannot open for writing");
  out << all.dump(2) << "\n";
}

std::string TimestampText(double t) { return std::isfinite(t) ? FormatTimestamp(t) : "nan"; }

std::string EventName(const SystemEvent& e) {
  switch (e.kind) {
    case SystemEvent::Kind::kKeyframeCreated:
      return "keyframe";
    case SystemEvent::Kind::kKeyframeFinished:
      return "finished";
    case SystemEvent::Kind::kGraphOptimised:
      return "optimised";
    case SystemEvent::Kind::kLost:
      return "lost";
    case SystemEvent::Kind::kRecovered:
      return "recovered";
    case SystemEvent::Kind::kPosesRevised:
      return "revised";
    case SystemEvent::Kind::kRestarted:
      return "restarted";
    case SystemEvent::Kind::kLoopClosed:
      return "loop:" + std::to_string(e.loop_keyframe_id);
    case SystemEvent::Kind::kRelocalised:
      return "relocalised:" + std::to_string(e.keyframe_id);
    case SystemEvent::Kind::kNewMap:
      return "new_map:" + std::to_string(e.map_id);
    case SystemEvent::Kind::kMapsMerged:
      return "merged:" + std::to_string(e.map_id);
    case SystemEvent::Kind::kDiverged:
      return "diverged:" + std::to_string(e.keyframe_id);
  }
  return "unknown";
}

}  // namespace

std::string EventNames(const std::vector<SystemEvent>& events, const FrameSuffix& other_frame) {
  std::string names;
  for (const SystemEvent& e : events) {
    if (!names.empty()) names += ';';
    names += EventName(e);
    if (other_frame) names += other_frame(e.frame_id);
  }
  return names;
}

RunOutputs::RunOutputs(const std::string& out_dir, RunOptions::TrajectoryFormat format,
                       const std::string& dataset)
    : out_dir_(out_dir), dataset_(dataset), format_(format) {
  std::error_code ec;
  fs::create_directories(out_dir_, ec);
  if (!fs::is_directory(out_dir_)) throw InputError(out_dir_, "cannot create the output folder");
  for (const std::string& name : OutputNames()) fs::remove(Path(name), ec);
  WriteManifest("running", {});  // fails here, before any frame, when the folder is read-only
  frame_log_.open(Path("frames.csv"));
  online_.open(Path("trajectory_online.txt"));
  if (format_ == RunOptions::TrajectoryFormat::kKitti) {
    online_times_.open(Path("trajectory_online.times.txt"));
  }
  if (!frame_log_ || !online_) throw InputError(out_dir_, "cannot write in the output folder");
  frame_log_ << "frame,timestamp,status,posed,keyframe,tracking_ms,mapping_ms,events\n";
}

std::string RunOutputs::Path(const std::string& name) const {
  return (fs::path(out_dir_) / name).string();
}

void RunOutputs::LogFrame(int index, double timestamp, std::int64_t frame_id,
                          const FrameResult& result) {
  index_of_frame_[frame_id] = index;
  // Events concern the frames mapping has not passed yet (a few dozen behind at most); the
  // engine's ids of successive calls are consecutive, so the oldest one kept goes.
  index_of_frame_.erase(frame_id - kFramesRemembered);
  const auto other_frame = [&](std::int64_t id) -> std::string {
    if (id == frame_id) return "";
    const auto known = index_of_frame_.find(id);
    return known == index_of_frame_.end() ? "" : "@" + std::to_string(known->second);
  };
  frame_log_ << fmt::format(
      "{},{},{},{},{},{:.3f},{:.3f},{}\n", index, TimestampText(timestamp),
      result.answered_before_mapping ? "initialising" : ToString(result.status),
      result.T_w_c ? 1 : 0, result.is_keyframe ? 1 : 0, result.tracking_ms, result.mapping_ms,
      EventNames(result.events, other_frame));
  frame_log_.flush();
  if (!result.T_w_c) return;
  const Trajectory one{{timestamp, *result.T_w_c}};
  if (format_ == RunOptions::TrajectoryFormat::kTum) {
    online_ << FormatTumLine(one.front()) << '\n';
  } else {
    online_ << FormatKittiLine(one.front()) << '\n';
    online_times_ << FormatTimestamp(timestamp) << '\n' << std::flush;
  }
  online_.flush();
}

void RunOutputs::LogUnreadable(int index, double timestamp, const std::string& unreadable) {
  std::string reason = unreadable;
  for (char& c : reason) {
    if (c == ',' || c == '\n') c = ' ';
  }
  frame_log_ << fmt::format("{},{},unreadable,0,0,0,0,{}\n", index, TimestampText(timestamp),
                            reason);
  frame_log_.flush();
}

void RunOutputs::LogDropped(int index, double timestamp) {
  frame_log_ << fmt::format("{},{},dropped,0,0,0,0,\n", index, TimestampText(timestamp));
  frame_log_.flush();
}

void RunOutputs::Finish(const System& system, RunSummary* summary, const std::string& status) {
  Trajectory trajectory;
  for (const FramePose& pose : system.Trajectory()) {
    trajectory.push_back({pose.timestamp, pose.T_w_c});
  }
  std::vector<std::string> files{"frames.csv", "trajectory_online.txt"};
  const bool kitti = format_ == RunOptions::TrajectoryFormat::kKitti;
  WriteAtomically(Path("trajectory.txt"), [&](const std::string& p) {
    kitti ? WriteKittiTrajectory(p, trajectory) : WriteTumTrajectory(p, trajectory);
  });
  files.push_back("trajectory.txt");
  if (kitti) {
    WriteAtomically(Path("trajectory.times.txt"), [&](const std::string& p) {
      std::ofstream times(p);
      for (const StampedPose& pose : trajectory) times << FormatTimestamp(pose.timestamp) << '\n';
      if (!times) throw InputError(p, "write failed");
    });
    files.insert(files.end(), {"trajectory.times.txt", "trajectory_online.times.txt"});
  }
  Trajectory keyframes;
  for (const KeyframeRecord& kf : system.Keyframes()) {
    keyframes.push_back({kf.timestamp, SE3d(kf.S_w_kf.Rotation(), kf.S_w_kf.Translation())});
  }
  WriteAtomically(Path("keyframes.txt"),
                  [&](const std::string& p) { WriteTumTrajectory(p, keyframes); });
  WriteAtomically(Path("map.ply"),
                  [&](const std::string& p) { summary->map_points = WritePly(p, system); });
  summary->status = status;
  WriteAtomically(Path("stats.json"), [&](const std::string& p) { WriteStats(p, *summary); });
  files.insert(files.end(), {"keyframes.txt", "map.ply", "stats.json"});
  WriteManifest(status, files);
}

void RunOutputs::WriteManifest(const std::string& status,
                               const std::vector<std::string>& files) const {
  const nlohmann::json j = {{"status", status},
                            {"complete", status == "complete"},
                            {"dataset", dataset_},
                            {"files", files}};
  WriteAtomically(Path("run.json"), [&](const std::string& p) {
    std::ofstream out(p);
    out << j.dump(2) << "\n";
    if (!out) throw InputError(p, "cannot write (is the output folder writable?)");
  });
}

}  // namespace parallax
