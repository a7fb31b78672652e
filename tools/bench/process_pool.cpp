#include "tools/bench/process_pool.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <map>

#include "tools/dataset/input_error.hpp"

extern char** environ;

namespace fs = std::filesystem;

namespace parallax::bench {
namespace {

pid_t Spawn(const ProcessJob& job) {
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
  const int error = posix_spawnp(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (error != 0) throw InputError(job.argv[0], "cannot start: " + std::string(strerror(error)));
  return pid;
}

}  // namespace

std::vector<ProcessOutcome> RunProcesses(const std::vector<ProcessJob>& jobs, int parallel,
                                         bool progress) {
  using Clock = std::chrono::steady_clock;
  struct Running {
    std::size_t job;
    Clock::time_point start;
  };
  std::vector<ProcessOutcome> outcomes(jobs.size());
  std::map<pid_t, Running> running;
  std::size_t next = 0, done = 0;
  const bool tty = isatty(STDERR_FILENO) != 0;
  const auto show = [&] {
    if (!progress) return;
    std::string names;
    for (const auto& [pid, r] : running) names += (names.empty() ? "" : ", ") + jobs[r.job].label;
    std::fprintf(stderr, "%s[%zu/%zu] running: %s%s", tty ? "\r\033[K" : "", done, jobs.size(),
                 names.c_str(), tty ? "" : "\n");
  };
  while (done < jobs.size()) {
    while (running.size() < static_cast<std::size_t>(parallel) && next < jobs.size()) {
      const Clock::time_point start = Clock::now();
      running[Spawn(jobs[next])] = {next, start};
      ++next;
    }
    show();
    int status = 0;
    const pid_t pid = waitpid(-1, &status, 0);
    if (pid < 0) throw std::runtime_error("bench: waitpid failed");
    const auto it = running.find(pid);
    if (it == running.end()) continue;
    ProcessOutcome& outcome = outcomes[it->second.job];
    outcome.wall_s = std::chrono::duration<double>(Clock::now() - it->second.start).count();
    outcome.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    running.erase(it);
    ++done;
  }
  if (progress)
    std::fprintf(stderr, "%s[%zu/%zu] done\n", tty ? "\r\033[K" : "", done, jobs.size());
  return outcomes;
}

std::string TailOf(const std::string& file, std::size_t lines) {
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

std::vector<std::string> Pinned(const std::string& cpus, std::vector<std::string> argv) {
  if (cpus.empty()) return argv;
  argv.insert(argv.begin(), {"taskset", "-c", cpus});
  return argv;
}

}  // namespace parallax::bench
