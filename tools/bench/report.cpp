#include "tools/bench/report.hpp"

#include <fmt/format.h>
#include <sys/utsname.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

#include "tools/dataset/input_error.hpp"

#ifndef PARALLAX_SOURCE_DIR
#define PARALLAX_SOURCE_DIR "."
#endif

namespace parallax::bench {
namespace {

nlohmann::json FiguresJson(const TrajectoryFigures& f) {
  nlohmann::json j = {{"estimate", f.estimate}, {"ok", f.ok}};
  if (!f.ok) {
    j["error"] = f.error;
    return j;
  }
  nlohmann::json kitti = nlohmann::json::array();
  for (const KittiSegmentError& k : f.kitti) {
    kitti.push_back({{"length", k.length},
                     {"translation_percent", k.translation_percent},
                     {"rotation_deg_per_100m", k.rotation_deg_per_100m}});
  }
  j.update(
      {{"ate_rmse", f.ate_rmse},
       {"ate_rmse_se3", f.ate_rmse_se3},
       {"ate_percent_of_path", f.ate_percent_of_path},
       {"coverage", f.coverage},
       {"rpe_per_frame",
        {{"translation", f.rpe_frame_translation}, {"rotation_deg", f.rpe_frame_rotation_deg}}},
       {"rpe_per_second_translation", f.rpe_second_translation},
       {"rpe_per_distance",
        {{"delta", f.rpe_distance_delta}, {"translation", f.rpe_distance_translation}}},
       {"kitti_segments", kitti}});
  return j;
}

std::string CommandOutput(const std::string& command) {
  std::string out;
  if (FILE* pipe = popen(command.c_str(), "r")) {
    char buffer[256];
    while (fgets(buffer, sizeof(buffer), pipe)) out += buffer;
    pclose(pipe);
  }
  while (!out.empty() && (out.back() == '\n' || out.back() == ' ')) out.pop_back();
  return out;
}

/// The source tree's commit, "+dirty" when it has uncommitted changes; "unknown" without git.
std::string Commit() {
  const std::string dir = PARALLAX_SOURCE_DIR;
  const std::string head =
      CommandOutput("git -C '" + dir + "' rev-parse --short=12 HEAD 2>/dev/null");
  if (head.empty()) return "unknown";
  const std::string dirty =
      CommandOutput("git -C '" + dir + "' status --porcelain --untracked-files=no 2>/dev/null");
  return dirty.empty() ? head : head + "+dirty";
}

std::string CpuModel() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  }
  return "unknown";
}

nlohmann::json Machine() {
  utsname u{};
  uname(&u);
  return {{"system", std::string(u.sysname) + " " + u.release},
          {"machine", u.machine},
          {"cpu", CpuModel()},
          {"cores", sysconf(_SC_NPROCESSORS_ONLN)},
          {"compiler", fmt::format("g++ {}.{}.{}", __GNUC__, __GNUC_MINOR__, __GNUC_PATCHLEVEL__)}};
}

std::string Cell(const RunRecord& r, const PeerFigures& p) {
  const TrajectoryFigures& f = p.figures;
  std::string cell = p.exit_code != 0 ? fmt::format("failed (exit {})", p.exit_code)
                     : !f.ok          ? std::string("failed")
                                      : fmt::format("{:.4f} m ({:.2f}%), {:.0f}%", f.ate_rmse,
                                                    f.ate_percent_of_path, 100.0 * f.coverage);
  if (p.timed) {
    cell += fmt::format(", {:.1f} ms/frame", p.ms_per_frame);
    if (r.Ok() && p.ms_per_frame > 0.0) {
      cell += fmt::format(" (parallax {:.2f}x its time)", r.process_ms_per_frame / p.ms_per_frame);
    }
  }
  return cell;
}

nlohmann::json PeerJson(const RunRecord& r, const PeerFigures& p) {
  nlohmann::json j = FiguresJson(p.figures);
  if (!p.timed) return j;
  j["ms_per_frame"] = p.ms_per_frame;
  j["exit_code"] = p.exit_code;
  if (!p.log_tail.empty()) j["log_tail"] = p.log_tail;
  // Whole-process time per frame, parallax over the peer (below 1: parallax is faster).
  j["time_ratio"] = p.ms_per_frame > 0.0 && r.Ok()
                        ? nlohmann::json(r.process_ms_per_frame / p.ms_per_frame)
                        : nlohmann::json();
  return j;
}

}  // namespace

std::string ReportJson(const BenchResult& result, const std::string& invocation) {
  nlohmann::json runs = nlohmann::json::array();
  for (const RunRecord& r : result.runs) {
    nlohmann::json run = {
        {"sequence", r.sequence},
        {"configuration", r.configuration},
        {"command", r.command},
        {"run_dir", r.run_dir},
        {"exit_code", r.exit_code},
        {"estimate", r.figures.estimate},
        {"groundtruth", r.groundtruth},
        {"ate_rmse", r.figures.ok ? nlohmann::json(r.figures.ate_rmse) : nlohmann::json()},
        {"coverage", r.figures.ok ? nlohmann::json(r.figures.coverage) : nlohmann::json()},
        {"figures", FiguresJson(r.figures)},
        {"frames", r.frames},
        {"frames_tracked", r.frames_tracked},
        {"keyframes", r.keyframes},
        {"loop_closures", r.loop_closures},
        {"fps", r.fps},
        {"fps_repeats", r.fps_repeats},
        {"process_ms_per_frame", r.process_ms_per_frame},
        {"tracking_ms", {{"p50", r.tracking_ms_p50}, {"p95", r.tracking_ms_p95}}},
        {"mapping_ms", {{"p50", r.mapping_ms_p50}, {"p95", r.mapping_ms_p95}}},
        {"optimisation_ms", {{"p50", r.optimisation_ms_p50}, {"p95", r.optimisation_ms_p95}}},
        {"peak_rss_mb", r.peak_rss_mb},
        {"repeats_identical", r.repeats_identical}};
    if (!r.log_tail.empty()) run["log_tail"] = r.log_tail;
    nlohmann::json peers = nlohmann::json::object();
    for (const auto& [name, p] : r.peers) peers[name] = PeerJson(r, p);
    run["peers"] = peers;
    runs.push_back(run);
  }
  nlohmann::json sequences = nlohmann::json::array();
  for (const SequenceSpec& s : result.suite.sequences) {
    sequences.push_back({{"name", s.name},
                         {"path", s.path},
                         {"format", s.format},
                         {"config", s.config},
                         {"max_frames", s.max_frames},
                         {"first_frame", s.first_frame},
                         {"rendered", s.synth.has_value()},
                         {"tolerance",
                          {{"ate_relative", s.tolerance.ate_relative},
                           {"ate_absolute", s.tolerance.ate_absolute},
                           {"coverage", s.tolerance.coverage}}}});
  }
  nlohmann::json configurations = nlohmann::json::array();
  for (const Configuration& c : result.suite.configurations) {
    configurations.push_back({{"name", c.name}, {"config", c.config}});
  }
  const nlohmann::json j = {{"suite", result.suite.name},
                            {"suite_file", result.suite.file},
                            {"command", invocation},
                            {"commit", Commit()},
                            {"machine", Machine()},
                            {"sequences", sequences},
                            {"configurations", configurations},
                            {"wall_s", result.wall_s},
                            {"runs", runs}};
  return j.dump(2) + "\n";
}

std::string ReportMarkdown(const BenchResult& result) {
  std::vector<std::string> peer_names;
  for (const RunRecord& r : result.runs) {
    for (const auto& [name, p] : r.peers) {
      if (std::find(peer_names.begin(), peer_names.end(), name) == peer_names.end()) {
        peer_names.push_back(name);
      }
    }
  }
  const bool configs = result.suite.configurations.size() > 1;
  std::string md = fmt::format(
      "Suite `{}`, commit {}, {} runs, {:.0f} s. ATE RMSE after Sim(3) alignment (and SE(3)), "
      "coverage = share of image frames with a pose; X = coverage below 90%.\n\n",
      result.suite.name, Commit(), result.runs.size(), result.wall_s);
  md += std::string("| sequence |") + (configs ? " configuration |" : "") +
        " ATE RMSE (Sim3) | % of path | ATE (SE3) | frames posed | keyframes | fps | process "
        "ms/frame | tracking ms p50/p95 | mapping ms p50/p95 | peak RSS |";
  for (const std::string& p : peer_names) md += " " + p + " |";
  md += "\n|---|" + std::string(configs ? "---|" : "") + "---|---|---|---|---|---|---|---|---|---|";
  for (std::size_t k = 0; k < peer_names.size(); ++k) md += "---|";
  md += "\n";
  for (const RunRecord& r : result.runs) {
    md += "| " + r.sequence + " |" + (configs ? " " + r.configuration + " |" : "");
    if (!r.Ok()) {
      md += fmt::format(" failed (exit {}) | | | | | | | | | |", r.exit_code);
    } else {
      const TrajectoryFigures& f = r.figures;
      md += fmt::format(
          " {:.4f} m | {:.2f}% | {:.4f} m | {}/{} ({:.0f}%){} | {} | {:.1f} | {:.1f} | {:.1f} / "
          "{:.1f} | {:.1f} / {:.1f} | {:.0f} MB |",
          f.ate_rmse, f.ate_percent_of_path, f.ate_rmse_se3, r.frames_tracked, r.frames,
          100.0 * f.coverage, f.coverage < 0.9 ? " X" : "", r.keyframes, r.fps,
          r.process_ms_per_frame, r.tracking_ms_p50, r.tracking_ms_p95, r.mapping_ms_p50,
          r.mapping_ms_p95, r.peak_rss_mb);
    }
    for (const std::string& p : peer_names) {
      const auto it = r.peers.find(p);
      md += " " + (it == r.peers.end() ? std::string("-") : Cell(r, it->second)) + " |";
    }
    md += "\n";
  }
  return md;
}

std::vector<Regression> CompareWithBaseline(const BenchResult& result,
                                            const std::string& baseline_file) {
  std::ifstream in(baseline_file);
  if (!in) throw InputError(baseline_file, "cannot open baseline");
  const nlohmann::json base = nlohmann::json::parse(in, nullptr, false);
  if (base.is_discarded() || !base.contains("runs")) {
    throw InputError(baseline_file, "not a report.json (no 'runs')");
  }
  std::vector<Regression> out;
  std::size_t index = 0;
  for (const SequenceSpec& s : result.suite.sequences) {
    for (const Configuration& c : result.suite.configurations) {
      const RunRecord& r = result.runs[index++];
      for (const nlohmann::json& b : base["runs"]) {
        if (b.value("sequence", "") != s.name || b.value("configuration", "") != c.name) continue;
        if (!b["ate_rmse"].is_number()) break;  // failed then: nothing to hold it to
        const double ate0 = b["ate_rmse"].get<double>();
        const double cov0 = b["coverage"].get<double>();
        if (!r.Ok()) {
          out.push_back({s.name, c.name,
                         fmt::format("run failed (exit {}{})", r.exit_code,
                                     r.figures.error.empty() ? "" : ", " + r.figures.error)});
          break;
        }
        const double allowed = std::max(ate0 * s.tolerance.ate_relative, s.tolerance.ate_absolute);
        if (r.figures.ate_rmse > ate0 + allowed) {
          out.push_back({s.name, c.name,
                         fmt::format("ATE {:.6f} -> {:.6f} m ({:+.0f}%, tolerance {:.0f}% or {} m)",
                                     ate0, r.figures.ate_rmse,
                                     100.0 * (r.figures.ate_rmse / std::max(ate0, 1e-12) - 1.0),
                                     100.0 * s.tolerance.ate_relative, s.tolerance.ate_absolute)});
        }
        if (r.figures.coverage < cov0 - s.tolerance.coverage) {
          out.push_back(
              {s.name, c.name,
               fmt::format("coverage {:.1f}% -> {:.1f}% (tolerance {:.1f} points)", 100.0 * cov0,
                           100.0 * r.figures.coverage, 100.0 * s.tolerance.coverage)});
        }
        break;
      }
    }
  }
  return out;
}

}  // namespace parallax::bench
