#include "tools/run_pipeline.hpp"

#include <fmt/format.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "core/check.hpp"
#include "core/stopwatch.hpp"
#include "core/undistorter.hpp"
#include "tools/dataset/camera_playback.hpp"
#include "tools/dataset/frame_prefetcher.hpp"
#include "tools/dataset/input_error.hpp"
#include "tools/dataset/photometric_corrector.hpp"
#include "tools/dataset/trajectory.hpp"
#include "tools/huge_page_heap.hpp"
#include "tools/run_outputs.hpp"

namespace parallax {
namespace {

double Percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  return values[static_cast<std::size_t>(std::lround(q * static_cast<double>(values.size() - 1)))];
}

}  // namespace

std::string RunSummary::Outcome() const {
  if (frames_tracked == 0) return "tracked_nothing";
  return 2 * frames_tracked >= frames ? "tracked" : "tracked_partially";
}

namespace {

struct Timings {
  std::vector<double> tracking_ms, mapping_ms, latency_ms, tracked_latency_ms;
};

/// Figures of the run so far (also for an interrupted or failed one).
void Summarise(const System& system, const Timings& timings,
               std::chrono::steady_clock::time_point start, RunSummary* summary) {
  const std::vector<double>& tracking_ms = timings.tracking_ms;
  const std::vector<double>& mapping_ms = timings.mapping_ms;
  summary->frames_tracked = static_cast<int>(system.Trajectory().size());
  summary->initialised_at_frame = system.InitialisedAtFrame();
  summary->frames_unusable = system.FramesUnusable();
  summary->wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  summary->fps = summary->frames / std::max(summary->wall_s, 1e-9);
  summary->keyframes = static_cast<int>(system.Keyframes().size());
  summary->tracking_ms_p50 = Percentile(tracking_ms, 0.5);
  summary->tracking_ms_p95 = Percentile(tracking_ms, 0.95);
  summary->mapping_ms_p50 = Percentile(mapping_ms, 0.5);
  summary->mapping_ms_p95 = Percentile(mapping_ms, 0.95);
  summary->edges = system.Graph().CountEdges();
  // One copy of the backend's counters (each Backend() call locks and copies its timings).
  const BackendStats backend = system.Backend();
  summary->optimisations = backend.optimisations;
  summary->optimisation_iterations = backend.iterations;
  summary->alignments = backend.alignments;
  summary->alignments_rejected = backend.edges_rejected;
  summary->optimisation_ms_p50 = Percentile(backend.optimisation_ms, 0.5);
  summary->optimisation_ms_p95 = Percentile(backend.optimisation_ms, 0.95);
  summary->graph_bytes = system.Graph().Bytes();
  summary->loop_candidates = backend.loop_candidates;
  summary->loop_checks = backend.loop_checks;
  summary->loops_rejected = backend.loops_rejected;
  summary->loops_closed = backend.loops_closed;
  summary->loop_ms_p50 = Percentile(backend.loop_ms, 0.5);
  summary->loop_ms_p95 = Percentile(backend.loop_ms, 0.95);
  summary->place_bytes = system.PlaceRecognitionBytes();
  summary->relocalisations = backend.relocalisations;
  summary->relocalisation_attempts = backend.relocalisation_attempts;
  summary->maps = system.Graph().NumMaps();
  summary->maps_started = backend.maps_started;
  summary->merges = backend.merges;
  summary->frames_diverged = backend.frames_diverged;
  summary->depth_estimates_diverged = backend.depth_estimates_diverged;
  summary->keyframes_diverged = backend.keyframes_diverged;
  summary->backend_steps_diverged = backend.backend_steps_diverged;
  summary->latency_ms_p50 = Percentile(timings.latency_ms, 0.5);
  summary->latency_ms_p95 = Percentile(timings.latency_ms, 0.95);
  summary->latency_ms_max = Percentile(timings.latency_ms, 1.0);
  summary->tracked_latency_ms_p50 = Percentile(timings.tracked_latency_ms, 0.5);
  summary->tracked_latency_ms_p95 = Percentile(timings.tracked_latency_ms, 0.95);
  summary->tracked_latency_ms_max = Percentile(timings.tracked_latency_ms, 1.0);
  summary->mapping = system.Realtime();
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  summary->peak_rss_mb = static_cast<double>(usage.ru_maxrss) / 1024.0;
  summary->heap_huge_pages = HeapUsesHugePages(std::getenv("GLIBC_TUNABLES"));
}

}  // namespace

namespace {

/// The frames as the run sees them: straight from the prefetcher, or through a live-camera
/// playback in the real-time mode with a rate (dropped frames are logged as such).
class FrameSource {
 public:
  FrameSource(FramePrefetcher* frames, const RunOptions& options)
      : frames_(frames), first_(static_cast<std::size_t>(options.first_frame)) {
    if (options.system.realtime.enabled && options.rate > 0.0) {
      playback_ = std::make_unique<CameraPlayback>(frames, options.rate, first_);
    }
  }
  std::optional<PreparedFrame> Next() {
    if (playback_) return playback_->Next();
    for (;;) {
      auto frame = frames_->Next();
      if (!frame || frame->index >= first_) return frame;
    }
  }
  std::vector<std::pair<std::size_t, double>> TakeDropped() {
    return playback_ ? playback_->TakeDropped() : std::vector<std::pair<std::size_t, double>>{};
  }

 private:
  FramePrefetcher* frames_;
  std::size_t first_;
  std::unique_ptr<CameraPlayback> playback_;
};

}  // namespace

RunSummary RunDataset(const RunOptions& options) {
  CheckArgument(options.max_frames >= 0, "--max-frames must be >= 0");
  CheckArgument(options.first_frame >= 0, "--first-frame must be >= 0");
  CheckArgument(options.rate >= 0.0 && std::isfinite(options.rate), "--rate must be >= 0");
  const auto reader = OpenDataset(options.dataset, options.dataset_options);
  const Undistorter undistorter(reader->GetCamera(), reader->SuggestedRectification());
  System system(undistorter.OutputCamera(), options.system);
  if (!options.load_map.empty()) system.LoadMap(options.load_map);
  RunOutputs outputs(options.out_dir, options.trajectory_format, options.dataset);
  Timings timings;
  RunSummary summary;
  summary.realtime = options.system.realtime.enabled;
  summary.rate = summary.realtime ? options.rate : 0.0;
  const auto start = std::chrono::steady_clock::now();
  const std::size_t num_frames = reader->NumFrames();  // the reader belongs to `frames` now
  std::optional<PhotometricCorrector> photometric;
  if (const auto calibration = reader->Photometric(); calibration && options.photometric) {
    // Checked when the dataset was opened (errors name its files).
    photometric.emplace(*calibration, reader->GetCamera().Width(), reader->GetCamera().Height());
  }
  summary.photometric = photometric && photometric->Enabled();
  // A calibration with nothing in it (no pcalib.txt, no vignette.png) is not applied.
  FramePrefetcher frames(reader.get(), &undistorter, 4, !options.fatal_unreadable,
                         summary.photometric ? &*photometric : nullptr);
  FrameSource source(&frames, options);
  const auto log_dropped = [&] {
    for (const auto& [index, timestamp] : source.TakeDropped()) {
      ++summary.frames;
      ++summary.frames_dropped;
      outputs.LogDropped(static_cast<int>(index), timestamp);
    }
  };
  try {
    while (options.max_frames == 0 || summary.frames < options.max_frames) {
      if (options.stop && options.stop->load()) {
        summary.status = "interrupted";
        break;
      }
      const auto frame = source.Next();
      log_dropped();
      if (!frame) break;
      ++summary.frames;
      if (!frame->error.empty()) {
        ++summary.frames_unreadable;
        std::fprintf(stderr, "%sparallax: skipping frame %zu: %s\n", options.progress ? "\n" : "",
                     frame->index, frame->error.c_str());
        outputs.LogUnreadable(static_cast<int>(frame->index), frame->timestamp, frame->error);
        continue;
      }
      const auto call = StageClock::now();
      const FrameResult result = system.ProcessFrame(frame->image, frame->timestamp);
      timings.latency_ms.push_back(MillisecondsSince(call));
      if (!result.answered_before_mapping)
        timings.tracked_latency_ms.push_back(timings.latency_ms.back());
      outputs.LogFrame(static_cast<int>(frame->index), frame->timestamp, system.NextFrameId() - 1,
                       result);
      timings.tracking_ms.push_back(result.tracking_ms);
      timings.mapping_ms.push_back(result.mapping_ms);
      if (options.progress && !summary.realtime) {
        std::fprintf(stderr, "\rframe %d/%zu  keyframes %zu  %s   ", summary.frames, num_frames,
                     system.Keyframes().size(), ToString(result.status).c_str());
      }
    }
    // Interrupted: what mapping has not reached is dropped (the keyframes made are kept);
    // otherwise every frame handed to mapping is mapped before the outputs.
    const auto shutdown = StageClock::now();
    if (summary.status == "interrupted") {
      system.StopMapping();
    } else {
      summary.end_events = EventNames(system.FinishMapping());
    }
    summary.shutdown_ms = MillisecondsSince(shutdown);
  } catch (const std::exception& e) {
    // A fatal input error: what the map holds is still written, marked failed.
    system.StopMapping();
    Summarise(system, timings, start, &summary);
    outputs.Finish(system, &summary, std::string("failed: ") + e.what());
    throw;
  }
  if (options.progress && !summary.realtime) std::fprintf(stderr, "\n");
  if (summary.frames == 0) throw InputError(options.dataset, "has no frames");
  Summarise(system, timings, start, &summary);
  outputs.Finish(system, &summary, summary.status);
  if (!options.save_map.empty()) system.SaveMap(options.save_map);
  return summary;
}

}  // namespace parallax
