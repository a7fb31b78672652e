#pragma once
// The files a run leaves behind (docs/cli.md, "parallax run"): checked writable before the run,
// stale ones of an earlier run removed, the live trajectory and the frame log streamed, and the
// final files written atomically (temporary file + rename) with a manifest, run.json, that
// says whether the run completed, was interrupted or failed.

#include <cstdint>
#include <fstream>
#include <functional>
#include <string>
#include <unordered_map>
#include <vector>

#include "backend/system.hpp"
#include "tools/dataset/trajectory.hpp"
#include "tools/run_pipeline.hpp"

namespace parallax {

/// Events in frames.csv's notation: `finished;optimised;loop:<keyframe id>;...`. An event
/// about another frame than the row's (the real-time mode reports what mapping did behind
/// the caller with the caller's next frame) gets `@<that frame's index>` from `other_frame`,
/// which returns "" for the row's own frame; without it nothing is appended.
using FrameSuffix = std::function<std::string(std::int64_t frame_id)>;
std::string EventNames(const std::vector<SystemEvent>& events,
                       const FrameSuffix& other_frame = nullptr);

class RunOutputs {
 public:
  /// Creates `out_dir` (throws InputError naming it when it cannot be created or written),
  /// removes the files an earlier run left there and marks the run as running in run.json.
  RunOutputs(const std::string& out_dir, RunOptions::TrajectoryFormat format,
             const std::string& dataset);

  /// One line of frames.csv and, for a posed frame, of trajectory_online.txt (both flushed,
  /// so an interrupted or crashed run keeps them). `frame_id`: the engine's id of the frame
  /// (System::NextFrameId() - 1 after it was processed).
  void LogFrame(int index, double timestamp, std::int64_t frame_id, const FrameResult& result);
  void LogUnreadable(int index, double timestamp, const std::string& unreadable);
  /// A frame the live camera replaced before tracking took it (real-time mode).
  void LogDropped(int index, double timestamp);

  /// trajectory.txt, keyframes.txt, map.ply and stats.json from the map as it stands, then
  /// run.json with `status` ("complete", "interrupted" or "failed: <reason>").
  void Finish(const System& system, RunSummary* summary, const std::string& status);

 private:
  std::string Path(const std::string& name) const;
  void WriteManifest(const std::string& status, const std::vector<std::string>& files) const;

  std::string out_dir_;
  std::string dataset_;
  RunOptions::TrajectoryFormat format_;
  std::ofstream frame_log_;
  std::ofstream online_;
  std::ofstream online_times_;  ///< KITTI format only
  /// The engine's frame id -> dataset index, for the last kFramesRemembered frames.
  static constexpr std::int64_t kFramesRemembered = 4096;
  std::unordered_map<std::int64_t, int> index_of_frame_;
};

}  // namespace parallax
