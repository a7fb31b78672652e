#include "tools/bench/bench_runner.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "tools/dataset/dataset_reader.hpp"
#include "tools/dataset/groundtruth_files.hpp"
#include "tools/dataset/input_error.hpp"

extern char** environ;

namespace fs = std::filesystem;

namespace parallax::bench {
namespace {

struct Job {
  std::size_t run_index = 0;  ///< into BenchResult::runs
  int repeat = 0;
  std::vector<std::string> argv;
  std::string dir;
};

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

pid_t Spawn(const Job& job) {
  fs::create_directories(job.dir);
  const std::string log = (fs::path(job.dir) / "run.log").string();
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  posix_spawn_file_actions_addclose(&actions, STDIN_FILENO);
  std::vector<char*> argv;
  for (const std::string& a : job.argv) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t pid = 0;
  const int error = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (error != 0) throw InputError(job.argv[0], "cannot start: " + std::string(strerror(error)));
  return pid;
}

std::string Tail(const std::string& file, std::size_t lines) {
  std::ifstream in(file);
  std::deque<std::string> last;
  std::string line;
  while (std::getline(in, line)) {
    last.push_back(line);
    if (last.size() > lines) last.pop_front();
  }
  std::string text;
  for (const std::string& l : last) text += l + "\n";
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

/// Runs the jobs, `jobs` at a time; returns each job's exit code (in job order).
std::vector<int> RunJobs(const std::vector<Job>& jobs, const BenchOptions& options,
                         const std::vector<RunRecord>& runs) {
  std::vector<int> codes(jobs.size(), -1);
  std::map<pid_t, std::size_t> running;
  std::size_t next = 0, done = 0;
  const bool tty = isatty(STDERR_FILENO) != 0;
  const auto show = [&] {
    if (!options.progress) return;
    std::string names;
    for (const auto& [pid, j] : running) {
      names += (names.empty() ? "" : ", ") + runs[jobs[j].run_index].sequence;
    }
    std::fprintf(stderr, "%s[%zu/%zu] running: %s%s", tty ? "\r\033[K" : "", done, jobs.size(),
                 names.c_str(), tty ? "" : "\n");
  };
  while (done < jobs.size()) {
    while (running.size() < static_cast<std::size_t>(options.jobs) && next < jobs.size()) {
      running[Spawn(jobs[next])] = next;
      ++next;
    }
    show();
    int status = 0;
    const pid_t pid = waitpid(-1, &status, 0);
    if (pid < 0) throw std::runtime_error("bench: waitpid failed");
    const auto it = running.find(pid);
    if (it == running.end()) continue;
    codes[it->second] = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    running.erase(it);
    ++done;
  }
  if (options.progress)
    std::fprintf(stderr, "%s[%zu/%zu] done\n", tty ? "\r\033[K" : "", done, jobs.size());
  return codes;
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
  RenderMissing(result.suite, options.progress);
  std::vector<Job> jobs;
  for (const SequenceSpec& s : result.suite.sequences) {
    for (const Configuration& c : result.suite.configurations) {
      RunRecord record;
      record.sequence = s.name;
      record.configuration = c.name;
      record.run_dir = (fs::absolute(options.out_dir) / "runs" / s.name / c.name).string();
      for (int k = 0; k < options.repeat; ++k) {
        const std::string dir = (fs::path(record.run_dir) / fmt::format("repeat{}", k)).string();
        jobs.push_back(
            {result.runs.size(), k, RunArguments(options.parallax_binary, s, c, dir), dir});
      }
      record.command = Join(jobs.back().argv);
      result.runs.push_back(std::move(record));
    }
  }
  const std::vector<int> codes = RunJobs(jobs, options, result.runs);
  for (std::size_t j = 0; j < jobs.size(); ++j) {
    RunRecord& r = result.runs[jobs[j].run_index];
    if (codes[j] != 0 && r.exit_code == 0) {
      r.exit_code = codes[j];
      r.log_tail = Tail((fs::path(jobs[j].dir) / "run.log").string(), 5);
    }
    if (codes[j] == 0) ReadStats(jobs[j].dir, &r, jobs[j].repeat == 0);
  }
  std::size_t index = 0;
  for (const SequenceSpec& s : result.suite.sequences) {
    for (std::size_t c = 0; c < result.suite.configurations.size(); ++c, ++index) {
      RunRecord& r = result.runs[index];
      r.fps = Median(r.fps_repeats);
      const std::string first = ReadAll(fs::path(r.run_dir) / "repeat0" / "trajectory.txt");
      for (int k = 1; k < options.repeat && r.exit_code == 0; ++k) {
        const fs::path other = fs::path(r.run_dir) / fmt::format("repeat{}", k) / "trajectory.txt";
        r.repeats_identical = r.repeats_identical && ReadAll(other) == first;
      }
      const std::string estimate = (fs::path(r.run_dir) / "repeat0" / "trajectory.txt").string();
      if (r.exit_code == 0) r.figures = EvaluateTrajectory(estimate, s, &r.groundtruth);
      for (const auto& [name, file] : s.peers) r.peers[name] = EvaluateTrajectory(file, s, nullptr);
    }
  }
  result.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace parallax::bench
