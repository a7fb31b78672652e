#pragma once
// Benchmark suites: which sequences (real or rendered on the fly), with which options, and
// the tolerances a regression check allows (docs/benchmarks.md, "The harness").

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "tools/synth/synthetic_sequence.hpp"

namespace parallax::bench {

/// How much worse a run may get than the baseline before it counts as a regression.
struct Tolerance {
  double ate_relative = 0.10;  ///< ATE may grow by this fraction ...
  double ate_absolute = 1e-4;  ///< ... or by this many metres, whichever is larger
  double coverage = 0.02;      ///< coverage may drop by this much (absolute)
};

struct SequenceSpec {
  std::string name;
  std::string path;  ///< dataset folder (absolute); for rendered ones, the cache folder
  std::string format = "auto";
  std::string calibration;  ///< calibration YAML, optional
  std::string groundtruth;  ///< file or folder; empty: the dataset's own
  std::string config;       ///< options YAML for parallax run, optional
  int max_frames = 0;       ///< first N frames (0: all)
  /// Frames before this dataset index are skipped (`parallax run --first-frame`): the same
  /// sequence started at another frame, for changes whose effect depends on where the
  /// keyframes fall (docs/benchmarks.md, "The harness"). A suite's `first_frames: [a, b]`
  /// makes one sequence per start, named `NAME@a`, `NAME@b`.
  int first_frame = 0;
  std::optional<synth::SynthOptions> synth;  ///< rendered on the fly when set
  Tolerance tolerance;
  std::map<std::string, std::string> peers;  ///< name -> another system's trajectory file
};

/// A named option set; every sequence runs once per configuration.
struct Configuration {
  std::string name = "default";
  std::string config;  ///< options YAML, optional (applied after the sequence's own)
  /// Set: the runs are `parallax run --realtime --rate R` (docs/realtime.md; 0 = as fast as
  /// tracking goes), so the report compares the modes on the same sequences.
  std::optional<double> realtime_rate;
};

struct Suite {
  std::string name;
  std::string file;
  std::vector<SequenceSpec> sequences;
  std::vector<Configuration> configurations;
};

/// Reads a suite. Paths are relative to the suite file; rendered sequences are cached under
/// `cache_dir` in a folder named by their parameters. Throws InputError naming the file and
/// line for unknown keys, missing paths, bad values or duplicate names.
Suite ReadSuite(const std::string& file, const std::string& cache_dir);

}  // namespace parallax::bench
