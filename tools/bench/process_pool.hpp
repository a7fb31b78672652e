#pragma once
// Child processes for parallax bench: each job's output goes to <dir>/run.log, N run at a time,
// each timed from spawn to exit (whole-process wall time, the figure peers are compared by).

#include <string>
#include <vector>

namespace parallax::bench {

struct ProcessJob {
  std::vector<std::string> argv;  ///< argv[0] is looked up in PATH when it has no '/'
  std::string dir;                ///< created; receives run.log (stdout and stderr)
  std::string label;              ///< shown in the progress line
};

struct ProcessOutcome {
  int exit_code = -1;  ///< 128 + signal when killed
  double wall_s = 0.0;
};

/// Runs `jobs`, `parallel` at a time; outcomes in job order. Throws InputError when a job
/// cannot be started (e.g. its program does not exist).
std::vector<ProcessOutcome> RunProcesses(const std::vector<ProcessJob>& jobs, int parallel,
                                         bool progress);

/// The last `lines` lines of a text file ("" when it cannot be read).
std::string TailOf(const std::string& file, std::size_t lines);

/// `argv` pinned to the CPUs in `cpus` (taskset's list syntax, e.g. "0" or "0,1"); unchanged
/// when `cpus` is empty.
std::vector<std::string> Pinned(const std::string& cpus, std::vector<std::string> argv);

}  // namespace parallax::bench
