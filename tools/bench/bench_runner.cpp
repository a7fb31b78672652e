#include "tools/bench/bench_runner.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "tools/bench/process_pool.hpp"
#include "tools/dataset/dataset_reader.hpp"
#include "tools/dataset/groundtruth_files.hpp"
#include "tools/dataset/input_error.hpp"

namespace fs = std::filesystem;

namespace parallax::bench {
namespace {

std::vector<std::string> RunArguments(const std::string& binary, const SequenceSpec& s,
                                      const Configuration& c, const std::string& dir) {
  std::vector<std::string> argv{binary, "run", s.path, "--out", dir, "--format", s.format};
  if (!s.calibration.empty()) argv.insert(argv.end(), {"--calib", s.calibration});
  if (!s.config.empty()) argv.insert(argv.end(), {"--config", s.config});
  if (!c.config.empty()) argv.insert(argv.end(), {"--config", c.config});
  if (c.realtime_rate) {
    argv.insert(argv.end(), {"--realtime", "--rate", std::to_string(*c.realtime_rate)});
  }
  if (s.max_frames > 0) argv.insert(argv.end(), {"--max-frames", std::to_string(s.max_frames)});
  if (s.first_frame > 0) {
    argv.insert(argv.end(), {"--first-frame", std::to_string(s.first_frame)});
  }
  return argv;
}

std::string Join(const std::vector<std::string>& argv) {
  std::string text;
  for (const std::string& a : argv) {
    if (!text.empty()) text += ' ';
    text += a.find(' ') == std::string::npos ? a : "'" + a + "'";
  }
  return text;
}

std::string ReadAll(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t mid = v.size() / 2;
  return v.size() % 2 ? v[mid] : 0.5 * (v[mid - 1] + v[mid]);
}

void RenderMissing(const Suite& suite, bool progress) {
  for (const SequenceSpec& s : suite.sequences) {
    if (!s.synth || fs::exists(fs::path(s.path) / "complete")) continue;
    if (progress) std::fprintf(stderr, "rendering %s -> %s\n", s.name.c_str(), s.path.c_str());
    const std::string partial = s.path + ".partial";
    fs::remove_all(partial);
    synth::WriteSyntheticSequence(*s.synth, partial);
    std::ofstream(fs::path(partial) / "complete") << "rendered by parallax bench\n";
    fs::remove_all(s.path);
    fs::rename(partial, s.path);
  }
}

void ReadStats(const std::string& dir, RunRecord* r, bool first) {
  std::ifstream in((fs::path(dir) / "stats.json").string());
  if (!in) return;
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  if (j.is_discarded()) return;
  r->fps_repeats.push_back(j.value("fps", 0.0));
  if (!first) return;
  r->frames = j.value("frames", 0);
  r->frames_tracked = j.value("frames_tracked", 0);
  r->keyframes = j.value("keyframes", 0);
  r->loop_closures = j.value("loop_closures", 0);
  r->peak_rss_mb = j.value("peak_rss_mb", 0.0);
  r->tracking_ms_p50 = j["tracking_ms"].value("p50", 0.0);
  r->tracking_ms_p95 = j["tracking_ms"].value("p95", 0.0);
  r->mapping_ms_p50 = j["mapping_ms"].value("p50", 0.0);
  r->mapping_ms_p95 = j["mapping_ms"].value("p95", 0.0);
  if (j.contains("keyframe_graph")) {
    r->optimisation_ms_p50 = j["keyframe_graph"]["optimisation_ms"].value("p50", 0.0);
    r->optimisation_ms_p95 = j["keyframe_graph"]["optimisation_ms"].value("p95", 0.0);
  }
}

}  // namespace

TrajectoryFigures EvaluateTrajectory(const std::string& estimate_file, const SequenceSpec& sequence,
                                     std::string* groundtruth_used) {
  TrajectoryFigures f;
  f.estimate = estimate_file;
  try {
    Trajectory groundtruth;
    EvaluationOptions options;
    const std::string gt = sequence.groundtruth.empty() ? sequence.path : sequence.groundtruth;
    if (groundtruth_used) *groundtruth_used = gt;
    if (fs::is_directory(gt)) {
      DatasetGroundTruth d = ReadDatasetGroundTruth(gt);
      groundtruth = std::move(d.poses);
    } else {
      groundtruth = ReadTrajectoryFile({gt, "", ""});
    }
    options.frame_timestamps = OpenDataset(sequence.path)->FrameTimestamps();
    if (sequence.max_frames > 0 &&
        options.frame_timestamps.size() > static_cast<std::size_t>(sequence.max_frames)) {
      options.frame_timestamps.resize(static_cast<std::size_t>(sequence.max_frames));
    }
    // The frames before the start are not the run's: they count neither as posed nor missed.
    const auto skipped =
        std::min(options.frame_timestamps.size(), static_cast<std::size_t>(sequence.first_frame));
    options.frame_timestamps.erase(
        options.frame_timestamps.begin(),
        options.frame_timestamps.begin() + static_cast<std::ptrdiff_t>(skipped));
    const Trajectory estimate = ReadTrajectoryFile({estimate_file, "", ""});
    const EvaluationReport sim3 = Evaluate(estimate, groundtruth, options);
    options.alignment = AlignmentMode::kSE3;
    const EvaluationReport se3 = Evaluate(estimate, groundtruth, options);
    f.ate_rmse = sim3.ate.rmse;
    f.ate_rmse_se3 = se3.ate.rmse;
    f.ate_percent_of_path = sim3.ate_rmse_percent_of_path;
    f.coverage = sim3.coverage;
    f.rpe_frame_translation = sim3.rpe_per_frame.translation.rmse;
    f.rpe_frame_rotation_deg = sim3.rpe_per_frame.rotation_deg.rmse;
    f.rpe_second_translation = sim3.rpe_per_second.translation.rmse;
    f.rpe_distance_translation = sim3.rpe_per_distance.translation.rmse;
    f.rpe_distance_delta = sim3.rpe_delta_meters;
    f.kitti = sim3.kitti;
    f.ok = true;
  } catch (const std::exception& e) {
    f.error = e.what();
  }
  return f;
}

namespace {

/// Image frames the runs see (the dataset's from first_frame, cut at max_frames).
std::size_t SequenceFrames(const SequenceSpec& s) {
  std::size_t n = OpenDataset(s.path)->FrameTimestamps().size();
  if (s.max_frames > 0) n = std::min(n, static_cast<std::size_t>(s.max_frames));
  return n - std::min(n, static_cast<std::size_t>(s.first_frame));
}

/// A job of the run list: which record (or peer of it) it belongs to.
struct JobOwner {
  std::size_t run_index = 0;  ///< into BenchResult::runs
  std::string peer;           ///< empty: the parallax run itself
  int repeat = 0;
};

struct JobList {
  std::vector<ProcessJob> jobs;
  std::vector<JobOwner> owners;
};

void AddRuns(const BenchOptions& options, BenchResult* result, JobList* list) {
  for (const SequenceSpec& s : result->suite.sequences) {
    const std::size_t first_of_sequence = result->runs.size();
    for (const Configuration& c : result->suite.configurations) {
      RunRecord record;
      record.sequence = s.name;
      record.configuration = c.name;
      record.run_dir = (fs::absolute(options.out_dir) / "runs" / s.name / c.name).string();
      for (int k = 0; k < options.repeat; ++k) {
        const std::string dir = (fs::path(record.run_dir) / fmt::format("repeat{}", k)).string();
        list->jobs.push_back(
            {Pinned(options.cpus, RunArguments(options.parallax_binary, s, c, dir)), dir, s.name});
        list->owners.push_back({result->runs.size(), "", k});
      }
      record.command = Join(list->jobs.back().argv);
      result->runs.push_back(std::move(record));
    }
    // A peer runs once per sequence; its figures go to every configuration's row.
    for (const PeerProgram& peer : options.peer_programs) {
      for (int k = 0; k < options.repeat; ++k) {
        const std::string dir = (fs::absolute(options.out_dir) / "runs" / s.name /
                                 ("peer-" + peer.name) / fmt::format("repeat{}", k))
                                    .string();
        const std::vector<std::string> argv{peer.command, s.path, dir,
                                            std::to_string(s.max_frames)};
        list->jobs.push_back({Pinned(options.cpus, argv), dir, s.name + " (" + peer.name + ")"});
        list->owners.push_back({first_of_sequence, peer.name, k});
      }
    }
  }
}

/// Peer program results of one sequence, from its jobs' outcomes.
std::map<std::string, PeerFigures> PeerResults(const JobList& list,
                                               const std::vector<ProcessOutcome>& outcomes,
                                               std::size_t run_index, const SequenceSpec& s,
                                               std::size_t frames) {
  std::map<std::string, std::vector<double>> walls;
  std::map<std::string, PeerFigures> peers;
  for (std::size_t j = 0; j < list.jobs.size(); ++j) {
    const JobOwner& owner = list.owners[j];
    if (owner.peer.empty() || owner.run_index != run_index) continue;
    PeerFigures& p = peers[owner.peer];
    p.timed = true;
    if (outcomes[j].exit_code != 0 && p.exit_code == 0) {
      p.exit_code = outcomes[j].exit_code;
      p.log_tail = TailOf((fs::path(list.jobs[j].dir) / "run.log").string(), 5);
    }
    // A peer that prepares its input first reports the time of its own process.
    double wall = outcomes[j].wall_s;
    if (std::ifstream reported(fs::path(list.jobs[j].dir) / "wall_seconds"); reported) {
      reported >> wall;
    }
    walls[owner.peer].push_back(wall);
    if (owner.repeat == 0) {
      p.figures =
          EvaluateTrajectory((fs::path(list.jobs[j].dir) / "trajectory.txt").string(), s, nullptr);
    }
  }
  for (auto& [name, p] : peers) {
    p.ms_per_frame =
        1e3 * Median(walls[name]) / static_cast<double>(std::max<std::size_t>(1, frames));
    if (p.exit_code != 0) p.figures.ok = false;
  }
  return peers;
}

}  // namespace

BenchResult RunBench(const std::string& suite_file, const BenchOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  CheckArgument(options.jobs >= 1 && options.repeat >= 1,
                "bench: --jobs and --repeat must be >= 1");
  fs::create_directories(options.out_dir);
  const std::string cache = options.cache_dir.empty()
                                ? (fs::path(options.out_dir) / "cache").string()
                                : options.cache_dir;
  BenchResult result;
  result.suite = ReadSuite(suite_file, cache);
  for (const SequenceSpec& s : result.suite.sequences) {
    // A peer program is given the dataset and a frame count, not a start.
    CheckArgument(options.peer_programs.empty() || s.first_frame == 0,
                  "bench: --peer cannot run '" + s.name + "' from its first_frames start");
  }
  RenderMissing(result.suite, options.progress);
  JobList list;
  AddRuns(options, &result, &list);
  const std::vector<ProcessOutcome> outcomes =
      RunProcesses(list.jobs, options.jobs, options.progress);
  std::vector<std::vector<double>> walls(result.runs.size());
  for (std::size_t j = 0; j < list.jobs.size(); ++j) {
    const JobOwner& owner = list.owners[j];
    if (!owner.peer.empty()) continue;
    RunRecord& r = result.runs[owner.run_index];
    const int code = outcomes[j].exit_code;
    if (code != 0 && r.exit_code == 0) {
      r.exit_code = code;
      r.log_tail = TailOf((fs::path(list.jobs[j].dir) / "run.log").string(), 5);
    }
    if (code == 0) ReadStats(list.jobs[j].dir, &r, owner.repeat == 0);
    walls[owner.run_index].push_back(outcomes[j].wall_s);
  }
  std::size_t index = 0;
  for (const SequenceSpec& s : result.suite.sequences) {
    const std::size_t frames = SequenceFrames(s);
    const std::map<std::string, PeerFigures> timed = PeerResults(list, outcomes, index, s, frames);
    for (std::size_t c = 0; c < result.suite.configurations.size(); ++c, ++index) {
      RunRecord& r = result.runs[index];
      r.fps = Median(r.fps_repeats);
      r.process_ms_per_frame =
          1e3 * Median(walls[index]) / static_cast<double>(std::max<std::size_t>(1, frames));
      const std::string first = ReadAll(fs::path(r.run_dir) / "repeat0" / "trajectory.txt");
      for (int k = 1; k < options.repeat && r.exit_code == 0; ++k) {
        const fs::path other = fs::path(r.run_dir) / fmt::format("repeat{}", k) / "trajectory.txt";
        r.repeats_identical = r.repeats_identical && ReadAll(other) == first;
      }
      const std::string estimate = (fs::path(r.run_dir) / "repeat0" / "trajectory.txt").string();
      if (r.exit_code == 0) r.figures = EvaluateTrajectory(estimate, s, &r.groundtruth);
      for (const auto& [name, file] : s.peers) {
        r.peers[name].figures = EvaluateTrajectory(file, s, nullptr);
      }
      for (const auto& [name, p] : timed) r.peers[name] = p;
    }
  }
  result.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace parallax::bench
