// The `parallax` command: one executable, one subcommand per user job (docs/cli.md).

#include <malloc.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>

#include "tools/commands/commands.hpp"
#include "tools/huge_page_heap.hpp"

namespace {

int Run(int argc, char** argv) {
  CLI::App app{"Parallax: direct semi-dense monocular SLAM"};
  app.require_subcommand(1);
  app.set_version_flag("--version", PARALLAX_VERSION);
  int exit_code = 0;
  parallax::cli::AddBenchCommand(app, &exit_code);
  parallax::cli::AddDemoCommand(app, &exit_code);
  parallax::cli::AddEvalCommand(app, &exit_code);
  parallax::cli::AddFramesCommand(app, &exit_code);
  parallax::cli::AddInfoCommand(app, &exit_code);
  parallax::cli::AddPosegraphCommand(app, &exit_code);
  parallax::cli::AddRunCommand(app, &exit_code);
  parallax::cli::AddSynthCommand(app, &exit_code);
  parallax::cli::AddVocabularyCommand(app, &exit_code);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  return exit_code;
}

}  // namespace

int main(int argc, char** argv) {
  // Before anything else: this may execute the program again (tools/huge_page_heap.hpp).
  parallax::RestartWithHugePageHeap(argv);
  // Frame pyramids, depth maps and their scratch images (about 1 MB each at 640x480) are
  // allocated and freed every frame. Mapped and unmapped each time (glibc's default for
  // large blocks), every page is faulted in again: measured, a third of the wall time of a
  // run on this machine. They come from the heap, kept (not trimmed) between frames, at
  // the price of RSS holding the peak of the short-lived buffers (docs/benchmarks.md,
  // "Memory and the allocator").
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
  mallopt(M_TOP_PAD, 64 << 20);
  // Every error reaches the user as one line on stderr and a non-zero exit, never a crash.
  try {
    return Run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "parallax: %s\n", e.what());
  } catch (...) {
    std::fprintf(stderr, "parallax: unknown error\n");
  }
  return 1;
}
