#pragma once
// Running the pipeline over a dataset and writing its outputs (design.md section 5).

#include <atomic>
#include <optional>
#include <string>

#include "backend/system.hpp"
#include "tools/dataset/dataset_reader.hpp"

namespace parallax {

struct RunOptions {
  std::string dataset;
  DatasetOptions dataset_options;
  std::string out_dir = "parallax_out";
  int max_frames = 0;  ///< 0: all
  /// Frames of the dataset before this index are read and skipped (not counted, not
  /// logged): a run over the second part of a sequence, e.g. on a map saved from the first.
  int first_frame = 0;
  /// A map file loaded before the first frame (the frames are relocalised on it and continue
  /// in its world frame), and one written at the end (docs/map_files.md); empty: none.
  std::string load_map;
  std::string save_map;
  SystemOptions system;
  bool progress = false;  ///< a progress line on stderr
  /// trajectory*.txt as TUM (timestamp tx ty tz qx qy qz qw) or KITTI (row-major 3x4 per
  /// posed frame, with the timestamps in trajectory*.times.txt beside it).
  enum class TrajectoryFormat { kTum, kKitti };
  TrajectoryFormat trajectory_format = TrajectoryFormat::kTum;
  /// An unreadable or corrupt image is skipped and reported (frames.csv, stats.json); with
  /// this it ends the run instead (its outputs are still written, marked failed).
  bool fatal_unreadable = false;
  /// Apply the dataset's photometric calibration (TUM monoVO response and vignette) when it
  /// has one (docs/datasets.md).
  bool photometric = true;
  /// Real-time mode (system.realtime.enabled): frames are played back at their timestamps
  /// divided by this (CameraPlayback; frames arriving while tracking is busy are dropped);
  /// 0 feeds them as fast as tracking takes them.
  double rate = 1.0;
  /// Polled between frames: when it becomes true the run stops and writes its outputs from
  /// the map as it stands, marked interrupted (SIGINT/SIGTERM in `parallax run`).
  const std::atomic<bool>* stop = nullptr;
};

struct RunSummary {
  int frames = 0;
  int frames_tracked = 0;
  int keyframes = 0;
  double wall_s = 0.0;
  double fps = 0.0;
  double tracking_ms_p50 = 0.0, tracking_ms_p95 = 0.0;
  double mapping_ms_p50 = 0.0, mapping_ms_p95 = 0.0;
  double peak_rss_mb = 0.0;
  /// glibc was asked to back the heap with huge pages (huge_page_heap.hpp); the kernel gives
  /// them where its transparent huge pages are not "never".
  bool heap_huge_pages = false;
  std::size_t map_points = 0;
  int initialised_at_frame = -1;  ///< -1: never initialised
  int frames_unusable = 0;        ///< rejected by the frame-quality gate
  int frames_unreadable = 0;      ///< unreadable or corrupt images, skipped
  /// "complete", "interrupted" or "failed: <reason>" (run.json and stats.json).
  std::string status = "complete";
  /// "tracked" (at least half the frames posed), "tracked_partially" or "tracked_nothing".
  std::string Outcome() const;
  /// Keyframe graph: edges by kind, optimisations and their cost.
  EdgeCounts edges;
  int optimisations = 0;
  int optimisation_iterations = 0;
  int alignments = 0;
  int alignments_rejected = 0;
  double optimisation_ms_p50 = 0.0, optimisation_ms_p95 = 0.0;
  std::size_t graph_bytes = 0;  ///< memory held by the finished keyframes
  /// Place recognition: database candidates, consistent ones verified, rejected, closed.
  int loop_candidates = 0;
  int loop_checks = 0;
  int loops_rejected = 0;
  int loops_closed = 0;
  double loop_ms_p50 = 0.0, loop_ms_p95 = 0.0;
  std::size_t place_bytes = 0;  ///< ORB features and vectors of the keyframes
  int relocalisations = 0;
  int relocalisation_attempts = 0;  ///< frames lost beyond the recent keyframes
  int maps = 0;                     ///< maps in the final graph (1 when every new map was merged)
  int maps_started = 0;             ///< new maps after long loss
  int merges = 0;
  /// Numerical divergence caught at stage boundaries (BackendStats, docs/reliability.md).
  int frames_diverged = 0;
  int depth_estimates_diverged = 0;
  int keyframes_diverged = 0;
  int backend_steps_diverged = 0;
  /// Wall time of each ProcessFrame call (what a caller waits for a pose), ms.
  double latency_ms_p50 = 0.0, latency_ms_p95 = 0.0, latency_ms_max = 0.0;
  /// The same over the calls that answered with tracking (a pose, or lost): without the
  /// start's frames answered before mapping (docs/realtime.md, "The CLI").
  double tracked_latency_ms_p50 = 0.0, tracked_latency_ms_p95 = 0.0, tracked_latency_ms_max = 0.0;
  /// Real-time mode only.
  bool realtime = false;
  double rate = 0.0;
  int frames_dropped = 0;  ///< arrived while tracking was busy: never processed, no pose
  RealtimeStats mapping;   ///< frames tracked live, waiting for mapping, skipped by mapping
  /// Wall time of the end of the run: FinishMapping (all input) or StopMapping (an
  /// interrupt: waiting work dropped), ms.
  double shutdown_ms = 0.0;
  /// Events of the end of the input (the last keyframe finished, a loop it closed), in
  /// frames.csv's notation; no frame row reports them.
  std::string end_events;
  bool photometric = false;  ///< the images were photometrically corrected
};

/// Reads the dataset, rectifies each image, runs System::ProcessFrame, and writes
/// out_dir/{trajectory.txt (every posed frame through the final, optimised keyframe graph),
/// trajectory_online.txt (the poses as reported live), keyframes.txt, map.ply, stats.json,
/// frames.csv (per frame: status, whether posed, keyframe, tracking and mapping ms, events)}.
/// With `save_map` the map is written after the outputs (also for an interrupted run).
/// Throws InputError for bad input (naming the file), MapFileError for a map file that
/// cannot be read or written, std::logic_error when there is no map to save, and
/// std::invalid_argument for bad options.
RunSummary RunDataset(const RunOptions& options);

}  // namespace parallax
