// System: finishing a keyframe (the graph, constraint search, optimisation, place
// recognition and loop closure, maps merged).
#include <chrono>
#include <mutex>
#include <shared_mutex>
#include <vector>

#include "backend/backend_worker.hpp"
#include "backend/system.hpp"
#include "core/divergence.hpp"
#include "core/stopwatch.hpp"

namespace parallax {
namespace {

using Clock = StageClock;

}  // namespace

void System::FinishCurrentKeyframe(FrameResult* result) {
  if (!mapper_.HasMap()) return;  // a loaded map before its first relocalisation
  const std::shared_ptr<Keyframe> keyframe = mapper_.Freeze();
  const bool is_new = !graph_.Contains(keyframe->id);
  graph_.Upsert(keyframe, CurrentKeyframePose(), current_map_);
  result->events.push_back({SystemEvent::Kind::kKeyframeFinished, result_frame_id_, keyframe->id});
  if (!options_.optimize_graph) {
    if (is_new && current_.parent) {
      graph_.AddEdge(PoseGraphEdge{*current_.parent, keyframe->id, current_.S_parent_kf,
                                   Matrix7d::Identity(), EdgeKind::kOdometry});
    }
    return;
  }
  FinishedKeyframe finished{keyframe->id, is_new ? current_.parent : std::nullopt,
                            current_.S_parent_kf};
  // Real-time mode: the backend thread takes it (RunBackendBatch).
  if (backend_worker_) {
    backend_pending_.push_back(finished);
    backend_worker_->Notify();
    return;
  }
  RunBackend(finished, result);
}

void System::RunBackend(const FinishedKeyframe& finished, FrameResult* result) {
  RunBackendOn(&graph_, finished, result_frame_id_, &backend_stats_, &result->events);
  chain_information_ = backend_.FallbackInformation();
  FollowMerges(result->events);
}

void System::RunBackendOn(KeyframeGraph* graph, const FinishedKeyframe& finished,
                          std::int64_t frame_id, BackendStats* stats,
                          std::vector<SystemEvent>* events) {
  const auto start = Clock::now();
  try {
    const BackendReport report =
        backend_.KeyframeFinished(graph, finished.id, finished.parent, finished.S_parent_kf);
    stats->alignments += report.alignments;
    stats->edges_rejected += report.edges_rejected;
    if (report.optimisation) {
      CountOptimisation(*report.optimisation, stats);
      stats->optimisation_ms.push_back(MillisecondsSince(start));
      events->push_back({SystemEvent::Kind::kGraphOptimised, frame_id, finished.id});
    }
    RecognisePlace(graph, finished.id, frame_id, stats, events);
  } catch (const NumericalDivergence&) {
    // Each edge and pose the step wrote before it diverged is a valid one (the groups check
    // themselves); the keyframe keeps at least the chain tracking made.
    AddChainEdges(graph, {finished});
    ++stats->backend_steps_diverged;
    events->push_back({SystemEvent::Kind::kDiverged, frame_id, finished.id});
  }
}

void System::CountOptimisation(const PoseGraphSummary& summary, BackendStats* stats) {
  ++stats->optimisations;
  stats->iterations += summary.iterations;
}

void System::RecognisePlace(KeyframeGraph* graph, std::int64_t id, std::int64_t frame_id,
                            BackendStats* stats, std::vector<SystemEvent>* events) {
  if (!options_.loop_closure.enabled && !options_.relocalization.enabled) return;
  {
    const std::shared_lock<std::shared_mutex> place(place_mutex_);
    if (place_.Contains(id)) return;  // refined again: its image did not change
  }
  const auto start = Clock::now();
  auto entry = place_.Describe(graph->Get(id).image);
  {
    const std::unique_lock<std::shared_mutex> place(place_mutex_);
    place_.Add(id, std::move(entry));
  }
  LoopReport loop;
  {
    const std::shared_lock<std::shared_mutex> place(place_mutex_);
    loop = loop_closer_.KeyframeFinished(graph, &backend_, id);
  }
  stats->loop_candidates += loop.candidates;
  stats->loop_checks += loop.consistent;
  stats->loops_rejected += loop.rejected;
  if (loop.optimisation) CountOptimisation(*loop.optimisation, stats);
  stats->loop_ms.push_back(MillisecondsSince(start));
  if (loop.merged_map) {
    ++stats->merges;
    SystemEvent merged{SystemEvent::Kind::kMapsMerged, frame_id, id, *loop.loop_keyframe};
    merged.map_id = *loop.merged_map;
    events->push_back(merged);
  }
  if (loop.loop_keyframe) {
    ++stats->loops_closed;
    events->push_back({SystemEvent::Kind::kLoopClosed, frame_id, id, *loop.loop_keyframe});
    events->push_back({SystemEvent::Kind::kGraphOptimised, frame_id, id});
  }
}

void System::FollowMerges(const std::vector<SystemEvent>& events) {
  for (const SystemEvent& e : events) {
    if (e.kind == SystemEvent::Kind::kMapsMerged && current_map_ == e.map_id) {
      current_map_ = graph_.MapOf(e.keyframe_id);
    }
  }
}

}  // namespace parallax
