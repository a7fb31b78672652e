#pragma once
// parallax bench: runs a suite's sequences as separate `parallax run` processes (N at a
// time, K repeats), evaluates every trajectory with tools/eval, and collects the figures
// (docs/benchmarks.md, "The harness"). It only orchestrates: metrics live in tools/eval.

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "tools/bench/suite.hpp"
#include "tools/eval/evaluation.hpp"

namespace parallax::bench {

/// Another system run on the same sequences in the same bench run: `command DATASET OUT_DIR
/// MAX_FRAMES` (MAX_FRAMES 0: all) must write OUT_DIR/trajectory.txt (TUM format) and exit 0.
/// It is timed as a whole process unless it writes OUT_DIR/wall_seconds (e.g. an adapter
/// that converts the input first and times only the system it runs).
/// scripts/peers/ has adapters (docs/benchmarks.md, "Side by side with a peer").
struct PeerProgram {
  std::string name;
  std::string command;
};

struct BenchOptions {
  std::string out_dir;
  int jobs = 1;
  int repeat = 1;
  std::string parallax_binary;  ///< the `parallax` executable that runs each sequence
  std::string cache_dir;        ///< rendered sequences; empty: <out_dir>/cache
  bool progress = true;         ///< a progress display on stderr
  /// Every process (parallax and peers) pinned to these CPUs (taskset list, e.g. "0");
  /// empty: not pinned. With a peer, use --jobs 1 so that nothing runs beside the timing.
  std::string cpus;
  std::vector<PeerProgram> peer_programs;
};

/// Figures of one trajectory against the ground truth.
struct TrajectoryFigures {
  std::string estimate;  ///< the file evaluated
  bool ok = false;
  std::string error;          ///< why it could not be evaluated
  double ate_rmse = 0.0;      ///< metres (ground-truth units), after Sim(3) alignment
  double ate_rmse_se3 = 0.0;  ///< after SE(3) alignment
  double ate_percent_of_path = 0.0;
  double coverage = 0.0;  ///< share of image frames with a pose
  double rpe_frame_translation = 0.0, rpe_frame_rotation_deg = 0.0;
  double rpe_second_translation = 0.0;
  double rpe_distance_translation = 0.0, rpe_distance_delta = 0.0;
  std::vector<KittiSegmentError> kitti;
};

/// A peer on one sequence: a trajectory file named by the suite (figures only), or a program
/// the harness ran (figures and whole-process time).
struct PeerFigures {
  TrajectoryFigures figures;
  bool timed = false;         ///< run by the harness (PeerProgram)
  int exit_code = 0;          ///< of the first failing repeat
  std::string log_tail;       ///< last lines of a failed run's output
  double ms_per_frame = 0.0;  ///< median whole-process wall time over the repeats / frames
};

/// One (sequence, configuration) run: medians over the repeats.
struct RunRecord {
  std::string sequence;
  std::string configuration;
  std::string command;  ///< the exact command of the first repeat
  std::string run_dir;
  std::string groundtruth;  ///< what the estimate was evaluated against
  int exit_code = 0;        ///< of the first failing repeat, else 0
  std::string log_tail;     ///< last lines of a failed run's output
  TrajectoryFigures figures;
  std::map<std::string, PeerFigures> peers;
  int frames = 0, frames_tracked = 0, keyframes = 0, loop_closures = 0;
  double fps = 0.0;  ///< median over repeats
  std::vector<double> fps_repeats;
  /// Median whole-process wall time (start-up and output included) / image frames: the
  /// figure compared with a timed peer's.
  double process_ms_per_frame = 0.0;
  double tracking_ms_p50 = 0.0, tracking_ms_p95 = 0.0;
  double mapping_ms_p50 = 0.0, mapping_ms_p95 = 0.0;
  double optimisation_ms_p50 = 0.0, optimisation_ms_p95 = 0.0;
  double peak_rss_mb = 0.0;
  /// With --repeat > 1: whether every repeat wrote the same trajectory.txt, byte for byte
  /// (the deterministic mode's promise); true for a single run.
  bool repeats_identical = true;
  bool Ok() const { return exit_code == 0 && figures.ok; }
};

struct BenchResult {
  Suite suite;
  std::vector<RunRecord> runs;  ///< in suite order: sequences, then configurations
  double wall_s = 0.0;
};

/// Renders missing synthetic sequences, runs everything, evaluates. Throws InputError for a
/// bad suite or output folder; a run that fails is recorded, not thrown.
BenchResult RunBench(const std::string& suite_file, const BenchOptions& options);

/// Evaluates `estimate` (TUM or KITTI file) against the sequence's ground truth.
TrajectoryFigures EvaluateTrajectory(const std::string& estimate, const SequenceSpec& sequence,
                                     std::string* groundtruth_used);

}  // namespace parallax::bench
