// The benchmark harness: suites, runs as processes (serial and parallel alike), figures equal
// to tools/eval on the same files, and the baseline check.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "temp_dir.hpp"
#include "tools/bench/bench_runner.hpp"
#include "tools/bench/report.hpp"
#include "tools/bench/suite.hpp"
#include "tools/dataset/groundtruth_files.hpp"
#include "tools/dataset/input_error.hpp"

namespace parallax::bench {
namespace {

using test::TempDir;

constexpr const char* kSuite =
    "name: tiny\n"
    "sequences:\n"
    "  - {name: room, synth: {scene: room, motion: shake, frames: 40, width: 320, height: 240}}\n"
    "  - name: corridor\n"
    "    synth: {scene: corridor, motion: walk, frames: 40, width: 320, height: 240}\n"
    "    tolerance: {ate_relative: 0.5}\n";

BenchOptions Options(const TempDir& dir, const std::string& out, int jobs) {
  BenchOptions o;
  o.out_dir = dir.File(out);
  o.cache_dir = dir.File("cache");
  o.jobs = jobs;
  o.parallax_binary = PARALLAX_BINARY;
  o.progress = false;
  return o;
}

// A suite `text` that ReadSuite refuses with an InputError naming `line` and `fragment`.
void ExpectSuiteErrorAt(const TempDir& dir, const std::string& text, int line,
                        const std::string& fragment) {
  try {
    ReadSuite(dir.Write("bad.yaml", text), dir.File("cache"));
    ADD_FAILURE() << text;
  } catch (const InputError& e) {
    EXPECT_EQ(e.Line(), line) << e.what();
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

TEST(BenchSuite, MinimalSuiteAndErrorsWithLines) {
  const TempDir dir;
  dir.Write("data/seq/rgb.txt", "");
  const Suite s = ReadSuite(dir.Write("s.yaml", "sequences:\n  - name: a\n    path: data/seq\n"),
                            dir.File("cache"));
  ASSERT_EQ(s.sequences.size(), 1u);
  EXPECT_EQ(s.sequences[0].path, std::filesystem::weakly_canonical(dir.File("data/seq")).string());
  EXPECT_EQ(s.configurations.size(), 1u);
  ExpectSuiteErrorAt(dir, "sequences:\n  - name: a\n    path: data/seq\n    colour: red\n", 4,
                     "unknown key");
  ExpectSuiteErrorAt(dir, "sequences:\n  - name: a\n    path: nowhere\n", 3, "does not exist");
  ExpectSuiteErrorAt(dir,
                     "sequences:\n  - {name: a, path: data/seq}\n  - {name: a, path: data/seq}\n",
                     3, "duplicate");
  ExpectSuiteErrorAt(dir, "sequences:\n  - {name: a, synth: {scene: room, frames: 1}}\n", 2,
                     "frames");
  ExpectSuiteErrorAt(dir,
                     "sequences:\n  - {name: a, path: data/seq}\nconfigurations:\n"
                     "  - {name: live, realtime_rate: -1}\n",
                     4, "realtime_rate");
  const Suite modes = ReadSuite(dir.Write("modes.yaml",
                                          "sequences:\n  - {name: a, path: data/seq}\n"
                                          "configurations:\n  - {name: deterministic}\n"
                                          "  - {name: camera, realtime_rate: 1}\n"),
                                dir.File("cache"));
  ASSERT_EQ(modes.configurations.size(), 2u);
  EXPECT_FALSE(modes.configurations[0].realtime_rate);
  EXPECT_EQ(modes.configurations[1].realtime_rate, 1.0);
}

TEST(BenchRunner, FiguresMatchEvalAndParallelEqualsSerial) {
  const TempDir dir;
  const std::string suite = dir.Write("tiny.yaml", kSuite);
  const BenchResult serial = RunBench(suite, Options(dir, "serial", 1));
  const BenchResult parallel = RunBench(suite, Options(dir, "parallel", 2));
  ASSERT_EQ(serial.runs.size(), 2u);
  ASSERT_EQ(parallel.runs.size(), 2u);
  for (std::size_t k = 0; k < serial.runs.size(); ++k) {
    const RunRecord& r = serial.runs[k];
    ASSERT_TRUE(r.Ok()) << r.sequence << ": " << r.log_tail << r.figures.error;
    EXPECT_GT(r.frames_tracked, 30) << r.sequence;
    // The same files through tools/eval directly.
    const Trajectory estimate = ReadTrajectoryFile({r.figures.estimate, "", ""});
    const Trajectory gt = ReadDatasetGroundTruth(r.groundtruth).poses;
    const EvaluationReport direct = Evaluate(estimate, gt, {});
    EXPECT_NEAR(r.figures.ate_rmse, direct.ate.rmse, 1e-12) << r.sequence;
    EXPECT_DOUBLE_EQ(r.figures.coverage, static_cast<double>(r.frames_tracked) / 40.0);
    // Deterministic runs: parallel execution changes nothing in the table.
    EXPECT_EQ(parallel.runs[k].figures.ate_rmse, r.figures.ate_rmse) << r.sequence;
    EXPECT_EQ(parallel.runs[k].frames_tracked, r.frames_tracked);
  }
  // report.json carries what the judge reads, per run.
  const nlohmann::json j = nlohmann::json::parse(ReportJson(serial, "test"));
  ASSERT_EQ(j["runs"].size(), 2u);
  for (const auto& run : j["runs"]) {
    for (const char* key :
         {"sequence", "estimate", "groundtruth", "ate_rmse", "coverage", "fps", "command"}) {
      EXPECT_TRUE(run.contains(key)) << key;
    }
  }
  EXPECT_NE(ReportMarkdown(serial).find("| corridor |"), std::string::npos);
  // Baseline: itself is no regression; a baseline with a much better corridor ATE is, and
  // the sequence is named.
  std::ofstream(dir.File("base.json")) << ReportJson(serial, "test");
  EXPECT_TRUE(CompareWithBaseline(parallel, dir.File("base.json")).empty());
  nlohmann::json better = j;
  for (auto& run : better["runs"]) {
    if (run["sequence"] == "corridor") run["ate_rmse"] = 0.5 * run["ate_rmse"].get<double>();
  }
  std::ofstream(dir.File("better.json")) << better.dump();
  const auto regressions = CompareWithBaseline(parallel, dir.File("better.json"));
  ASSERT_EQ(regressions.size(), 1u);
  EXPECT_EQ(regressions[0].sequence, "corridor");
  // Within the corridor's 50% tolerance: 0.7x the ATE is still no regression.
  for (auto& run : better["runs"]) {
    if (run["sequence"] == "corridor") run["ate_rmse"] = 1.4 * run["ate_rmse"].get<double>();
  }
  std::ofstream(dir.File("close.json")) << better.dump();
  EXPECT_TRUE(CompareWithBaseline(parallel, dir.File("close.json")).empty());
}

TEST(BenchRunner, RepeatsOfADeterministicRunAreIdentical) {
  const TempDir dir;
  BenchOptions options = Options(dir, "repeat", 2);
  options.repeat = 2;
  const std::string suite =
      "sequences:\n  - {name: room, synth: {scene: room, motion: shake, frames: 30, width: 320, "
      "height: 240}}\n";
  const BenchResult r = RunBench(dir.Write("one.yaml", suite), options);
  ASSERT_EQ(r.runs.size(), 1u);
  EXPECT_EQ(r.runs[0].fps_repeats.size(), 2u);
  EXPECT_TRUE(r.runs[0].repeats_identical);
}

// first_frames: one sequence per start, each run with --first-frame and judged on the frames
// from its start only (the skipped ones count neither as posed nor as missed).
TEST(BenchRunner, FirstFramesRunOneSequencePerStartJudgedFromItsStart) {
  const TempDir dir;
  const std::string suite =
      dir.Write("starts.yaml",
                "sequences:\n  - name: room\n    first_frames: [0, 12]\n"
                "    synth: {scene: room, motion: shake, frames: 40, width: 320, height: 240}\n");
  const Suite parsed = ReadSuite(suite, dir.File("cache"));
  ASSERT_EQ(parsed.sequences.size(), 2u);
  EXPECT_EQ(parsed.sequences[0].name, "room@0");
  EXPECT_EQ(parsed.sequences[1].name, "room@12");
  EXPECT_EQ(parsed.sequences[1].first_frame, 12);
  EXPECT_EQ(parsed.sequences[0].path, parsed.sequences[1].path);  // rendered once
  const BenchResult r = RunBench(suite, Options(dir, "out", 2));
  ASSERT_EQ(r.runs.size(), 2u);
  const RunRecord& late = r.runs[1];
  ASSERT_TRUE(late.Ok()) << late.log_tail << late.figures.error;
  EXPECT_NE(late.command.find("--first-frame 12"), std::string::npos) << late.command;
  EXPECT_EQ(r.runs[0].command.find("--first-frame"), std::string::npos);
  EXPECT_GT(late.frames_tracked, 20);
  EXPECT_DOUBLE_EQ(late.figures.coverage, static_cast<double>(late.frames_tracked) / 28.0);
  const Trajectory estimate = ReadTrajectoryFile({late.figures.estimate, "", ""});
  const Trajectory gt = ReadDatasetGroundTruth(late.groundtruth).poses;
  ASSERT_FALSE(estimate.empty());
  EXPECT_GE(estimate.front().timestamp, gt[12].timestamp - 1e-9);
  const nlohmann::json j = nlohmann::json::parse(ReportJson(r, "test"));
  EXPECT_EQ(j["sequences"][1]["first_frame"], 12);
  // A peer program would run from frame 0: refused before anything runs.
  BenchOptions with_peer = Options(dir, "peer", 1);
  with_peer.peer_programs.push_back({"dso", "/bin/true"});
  EXPECT_THROW(RunBench(suite, with_peer), std::invalid_argument);
  // Errors name the line: a start beyond the frames, a start with a peer's trajectory.
  dir.Write("data/seq/rgb.txt", "");
  dir.Write("data/peer.txt", "");
  ExpectSuiteErrorAt(dir,
                     "sequences:\n  - name: a\n    path: data/seq\n    max_frames: 10\n"
                     "    first_frames: [2, 10]\n",
                     5, "below max_frames");
  ExpectSuiteErrorAt(dir, "sequences:\n  - name: a\n    path: data/seq\n    first_frames: [x]\n", 4,
                     "integers");
  ExpectSuiteErrorAt(dir,
                     "sequences:\n  - name: a\n    path: data/seq\n    first_frames: [1]\n"
                     "    peers: {dso: data/peer.txt}\n",
                     4, "peers");
  ExpectSuiteErrorAt(dir,
                     "sequences:\n  - {name: a@1, path: data/seq}\n"
                     "  - {name: a, path: data/seq, first_frames: [1]}\n",
                     3, "duplicate");
}

TEST(BenchRunner, PeersAreEvaluatedLikeTheRun) {
  const TempDir dir;
  // The peer is the ground truth itself: zero error, full coverage.
  std::string suite = kSuite;
  const BenchResult first = RunBench(dir.Write("tiny.yaml", suite), Options(dir, "a", 2));
  const std::string gt = first.runs[0].groundtruth + "/groundtruth.txt";
  suite = std::string(
              "name: peers\nsequences:\n  - name: room\n    synth: {scene: room, motion: "
              "shake, frames: 40, width: 320, height: 240}\n    peers: {truth: ") +
          gt + "}\n";
  const BenchResult r = RunBench(dir.Write("peers.yaml", suite), Options(dir, "b", 1));
  ASSERT_EQ(r.runs.size(), 1u);
  ASSERT_EQ(r.runs[0].peers.count("truth"), 1u);
  const TrajectoryFigures& peer = r.runs[0].peers.at("truth").figures;
  EXPECT_FALSE(r.runs[0].peers.at("truth").timed);
  ASSERT_TRUE(peer.ok) << peer.error;
  EXPECT_LT(peer.ate_rmse, 1e-6);
  EXPECT_DOUBLE_EQ(peer.coverage, 1.0);
  EXPECT_NE(ReportMarkdown(r).find("truth"), std::string::npos);
}

// A peer program runs on every sequence in the same bench run, pinned like parallax, and is
// timed as a whole process; a failing one is reported, not thrown.
TEST(BenchRunner, PeerProgramsAreRunTimedAndEvaluated) {
  const TempDir dir;
  // "truth" answers with the ground truth after 0.4 s and records its arguments.
  const std::string truth =
      dir.Write("truth.sh",
                "#!/bin/sh\nsleep 0.4\nmkdir -p \"$2\"\necho \"$3\" > \"$2/max_frames\"\n"
                "cp \"$1/groundtruth.txt\" \"$2/trajectory.txt\"\n");
  const std::string broken = dir.Write("broken.sh", "#!/bin/sh\necho no input >&2\nexit 3\n");
  // "timer" times its own system: 3 s, whatever its whole process took.
  const std::string timer =
      dir.Write("timer.sh",
                "#!/bin/sh\ncp \"$1/groundtruth.txt\" \"$2/trajectory.txt\"\necho 3.0 > "
                "\"$2/wall_seconds\"\n");
  for (const std::string& f : {truth, broken, timer}) {
    std::filesystem::permissions(f, std::filesystem::perms::owner_exec,
                                 std::filesystem::perm_options::add);
  }
  const std::string suite =
      "name: peers\nsequences:\n  - name: room\n    max_frames: 30\n    synth: {scene: room, "
      "motion: shake, frames: 40, width: 320, height: 240}\n";
  BenchOptions options = Options(dir, "p", 1);
  options.cpus = "0";
  options.peer_programs = {{"truth", truth}, {"broken", broken}, {"timer", timer}};
  const BenchResult r = RunBench(dir.Write("peers.yaml", suite), options);
  ASSERT_EQ(r.runs.size(), 1u);
  ASSERT_TRUE(r.runs[0].Ok());
  EXPECT_GT(r.runs[0].process_ms_per_frame, 0.0);
  EXPECT_EQ(r.runs[0].command.rfind("taskset -c 0 ", 0), 0u) << r.runs[0].command;
  const PeerFigures& good = r.runs[0].peers.at("truth");
  EXPECT_TRUE(good.timed);
  ASSERT_TRUE(good.figures.ok) << good.figures.error;
  EXPECT_LT(good.figures.ate_rmse, 1e-6);
  EXPECT_GE(good.ms_per_frame, 400.0 / 30.0);  // 0.4 s over the 30 frames the runs see
  std::ifstream max_frames(r.runs[0].run_dir + "/../peer-truth/repeat0/max_frames");
  int n = 0;
  max_frames >> n;
  EXPECT_EQ(n, 30);
  EXPECT_DOUBLE_EQ(r.runs[0].peers.at("timer").ms_per_frame, 3000.0 / 30.0);
  const PeerFigures& bad = r.runs[0].peers.at("broken");
  EXPECT_EQ(bad.exit_code, 3);
  EXPECT_FALSE(bad.figures.ok);
  EXPECT_NE(bad.log_tail.find("no input"), std::string::npos);
  const std::string md = ReportMarkdown(r);
  EXPECT_NE(md.find("its time)"), std::string::npos) << md;
  EXPECT_NE(md.find("failed (exit 3)"), std::string::npos) << md;
  const nlohmann::json j = nlohmann::json::parse(ReportJson(r, "test"));
  EXPECT_TRUE(j["runs"][0]["peers"]["truth"]["time_ratio"].is_number());
}

}  // namespace
}  // namespace parallax::bench
