#include "backend/loop_closer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "backend/keypoint_depth.hpp"
#include "core/check.hpp"

namespace parallax {

void LoopClosureOptions::Check() const {
  place.Check();
  ransac.Check();
  optimizer.Check();
  CheckOption(exclude_recent_keyframes >= 0, "LoopClosureOptions", "exclude_recent_keyframes",
              "must be >= 0");
  CheckOption(min_score >= 0.0 && min_score <= 1.0, "LoopClosureOptions", "min_score",
              "must be in [0, 1]");
  CheckOption(max_candidates >= 1, "LoopClosureOptions", "max_candidates", "must be >= 1");
  CheckOption(consistency >= 1, "LoopClosureOptions", "consistency", "must be >= 1");
  CheckOption(min_matches >= 3, "LoopClosureOptions", "min_matches", "must be >= 3");
  CheckOption(max_reciprocal_translation > 0.0 && max_reciprocal_rotation_deg > 0.0 &&
                  max_reciprocal_log_scale > 0.0,
              "LoopClosureOptions", "max_reciprocal_translation",
              "and the other bounds must be > 0");
  CheckOption(max_correction_per_path > 0.0, "LoopClosureOptions", "max_correction_per_path",
              "must be > 0");
  CheckOption(reciprocal_median > 0.0, "LoopClosureOptions", "reciprocal_median", "must be > 0");
  CheckOption(max_relative_depth_std > 0.0, "LoopClosureOptions", "max_relative_depth_std",
              "must be > 0");
}

std::set<std::int64_t> ConnectedKeyframes(const KeyframeGraph& graph, std::int64_t id) {
  std::set<std::int64_t> connected;
  for (const PoseGraphEdge& e : graph.Poses().Edges()) {
    if (e.i == id) connected.insert(e.j);
    if (e.j == id) connected.insert(e.i);
  }
  return connected;
}

LoopCloser::LoopCloser(const LoopClosureOptions& options, const PlaceRecognizer* recognizer,
                       const PinholeCamera& camera)
    : options_(options), camera_(camera), recognizer_(recognizer), optimizer_(options.optimizer) {
  options_.Check();
}

void LoopCloser::Clear() { groups_.clear(); }

std::vector<DatabaseMatch> LoopCloser::Candidates(const KeyframeGraph& graph, std::int64_t id,
                                                  LoopReport* report) const {
  const std::set<std::int64_t> connected = ConnectedKeyframes(graph, id);
  const BowVector& bow = recognizer_->Entry(id).bow;
  double min_score = 1.0;
  for (const std::int64_t other : connected) {
    if (recognizer_->Contains(other)) {
      min_score = std::min(min_score, ScoreL1(bow, recognizer_->Entry(other).bow));
    }
  }
  if (connected.empty()) min_score = 0.0;
  min_score = std::max(min_score, options_.min_score);
  // The current neighbourhood: connected keyframes and the ones just before this one.
  const std::vector<std::int64_t> ids = graph.Ids();
  const auto position = std::lower_bound(ids.begin(), ids.end(), id) - ids.begin();
  const std::int64_t first_recent = ids[static_cast<std::size_t>(
      std::max<std::ptrdiff_t>(0, position - options_.exclude_recent_keyframes))];
  const auto excluded = [&](std::int64_t other) {
    return other == id || connected.count(other) > 0 || (other >= first_recent && other <= id);
  };
  auto matches = recognizer_->Database().Query(
      bow, excluded, static_cast<std::size_t>(options_.max_candidates), min_score);
  report->candidates = static_cast<int>(matches.size());
  return matches;
}

std::vector<DatabaseMatch> LoopCloser::KeepConsistent(
    const KeyframeGraph& graph, const std::vector<DatabaseMatch>& candidates) {
  std::vector<std::pair<std::set<std::int64_t>, int>> groups;
  std::vector<DatabaseMatch> consistent;
  for (const DatabaseMatch& c : candidates) {
    std::set<std::int64_t> group = ConnectedKeyframes(graph, c.keyframe_id);
    group.insert(c.keyframe_id);
    int seen = 1;
    for (const auto& previous : groups_) {
      const bool shares = std::any_of(group.begin(), group.end(),
                                      [&](std::int64_t k) { return previous.first.count(k) > 0; });
      if (shares) seen = std::max(seen, previous.second + 1);
    }
    if (seen >= options_.consistency) consistent.push_back(c);
    groups.emplace_back(std::move(group), seen);
  }
  groups_ = std::move(groups);
  return consistent;
}

double LoopCloser::CorrectionPerPath(const KeyframeGraph& graph, std::int64_t candidate,
                                     std::int64_t id, const Sim3d& S_cand_new) {
  const Sim3d& S_w_cand = graph.Pose(candidate);
  const Sim3d S_cand_new_graph = S_w_cand.Inverse() * graph.Pose(id);
  const double correction =
      S_w_cand.Scale() * (S_cand_new_graph.Translation() - S_cand_new.Translation()).norm();
  double path = 0.0;
  const std::vector<std::int64_t> ids = graph.Ids();
  for (std::size_t k = 1; k < ids.size(); ++k) {
    if (ids[k - 1] < std::min(candidate, id) || ids[k] > std::max(candidate, id)) continue;
    path += (graph.Pose(ids[k]).Translation() - graph.Pose(ids[k - 1]).Translation()).norm();
  }
  return path > 0.0 ? correction / path : std::numeric_limits<double>::infinity();
}

std::vector<PointMatch3d> LoopCloser::LiftMatches(const KeyframeGraph& graph, std::int64_t a,
                                                  std::int64_t b) const {
  const PlaceEntry& ea = recognizer_->Entry(a);
  const PlaceEntry& eb = recognizer_->Entry(b);
  const KeypointDepth depth_a(graph.Get(a).depth, camera_, options_.max_relative_depth_std);
  const KeypointDepth depth_b(graph.Get(b).depth, camera_, options_.max_relative_depth_std);
  std::vector<PointMatch3d> lifted;
  for (const auto& [i, j] : MatchByNodes(ea, eb, options_.place)) {
    const auto p_a = depth_a.Point(ea.features.pixel[i]);
    const auto p_b = depth_b.Point(eb.features.pixel[j]);
    if (!p_a || !p_b) continue;
    PointMatch3d m;
    m.p_a = *p_a;
    m.p_b = *p_b;
    m.px_a = ea.features.pixel[i].cast<double>();
    m.px_b = eb.features.pixel[j].cast<double>();
    m.sigma_a = OctaveScale(options_.place.orb, ea.features.octave[i]);
    m.sigma_b = OctaveScale(options_.place.orb, eb.features.octave[j]);
    lifted.push_back(m);
  }
  return lifted;
}

std::optional<GraphBackend::Alignment> LoopCloser::Verify(const KeyframeGraph& graph,
                                                          GraphBackend* backend, std::int64_t id,
                                                          std::int64_t candidate,
                                                          LoopReport* report) const {
  const std::vector<PointMatch3d> matches = LiftMatches(graph, candidate, id);
  const std::string name = "keyframe " + std::to_string(candidate) + ": ";
  if (static_cast<int>(matches.size()) < options_.min_matches) {
    report->rejections.push_back(name + std::to_string(matches.size()) + " matches with depth");
    return std::nullopt;
  }
  const Sim3RansacResult ransac = EstimateSim3Ransac(matches, camera_, options_.ransac);
  if (!ransac.found) {
    report->rejections.push_back(name + "no Sim(3) with enough inliers among " +
                                 std::to_string(matches.size()) + " matches");
    return std::nullopt;
  }
  const GraphBackend::Alignment a =
      backend->Align(graph, candidate, id, ransac.S_a_b, options_.accept_poor_alignment);
  if (!a.converged) {
    report->rejections.push_back(name + "direct alignment did not converge both ways");
    return std::nullopt;
  }
  const Sim3d disagreement = a.S_a_b_reverse.Inverse() * a.S_a_b;
  const double rotation_deg = disagreement.Rotation().Log().norm() * 180.0 / 3.14159265358979323846;
  if (disagreement.Translation().norm() > options_.max_reciprocal_translation ||
      rotation_deg > options_.max_reciprocal_rotation_deg ||
      std::abs(std::log(disagreement.Scale())) > options_.max_reciprocal_log_scale) {
    report->rejections.push_back(name + "the two directions of the direct alignment disagree");
    return std::nullopt;
  }
  // Between two maps there is no path and no drift to bound: the other gates decide.
  const bool same_map = graph.MapOf(candidate) == graph.MapOf(id);
  const double correction = same_map ? CorrectionPerPath(graph, candidate, id, a.S_a_b) : 0.0;
  if (!(correction <= options_.max_correction_per_path)) {
    report->rejections.push_back(
        name + "the correction is " +
        (std::isfinite(correction) ? std::to_string(std::lround(100.0 * std::min(correction, 1e6)))
                                   : std::string("unbounded")) +
        "% of the path between the keyframes");
    return std::nullopt;
  }
  GraphBackend::Alignment loop = a;
  if (a.reciprocal_distance > options_.reciprocal_median) {
    loop.information *= options_.reciprocal_median / a.reciprocal_distance;
  }
  report->ransac_inliers = static_cast<int>(ransac.inliers.size());
  return loop;
}

LoopReport LoopCloser::KeyframeFinished(KeyframeGraph* graph, GraphBackend* backend,
                                        std::int64_t id) {
  LoopReport report;
  if (!options_.enabled || !recognizer_->Contains(id)) return report;
  const auto consistent = KeepConsistent(*graph, Candidates(*graph, id, &report));
  report.consistent = static_cast<int>(consistent.size());
  for (const DatabaseMatch& candidate : consistent) {
    const auto loop = Verify(*graph, backend, id, candidate.keyframe_id, &report);
    if (!loop) {
      ++report.rejected;
      continue;
    }
    const int map = graph->MapOf(id);
    const int candidate_map = graph->MapOf(candidate.keyframe_id);
    if (map != candidate_map) {
      // The new keyframe's map moves into the candidate's world: S_wA_new = S_wA_cand *
      // S_cand_new, so S_A_B = S_wA_cand * S_cand_new * S_wB_new^-1.
      const Sim3d S_A_B =
          graph->Pose(candidate.keyframe_id) * loop->S_a_b * graph->Pose(id).Inverse();
      graph->MergeMaps(map, candidate_map, S_A_B);
      report.merged_map = map;
    }
    graph->AddEdge(
        PoseGraphEdge{candidate.keyframe_id, id, loop->S_a_b, loop->information, EdgeKind::kLoop});
    report.loop_keyframe = candidate.keyframe_id;
    report.optimisation = optimizer_.Optimize(&graph->Poses());
    groups_.clear();  // the loop's neighbourhood is connected now
    break;
  }
  return report;
}

}  // namespace parallax
