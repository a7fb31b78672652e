// parallax demo: the README's main job.

#include <cstdio>

#include "tools/commands/commands.hpp"

namespace parallax::cli {

void AddDemoCommand(CLI::App& app, int* exit_code) {
  CLI::App* cmd = app.add_subcommand("demo", "Run the pipeline on a built-in synthetic sequence");
  cmd->callback([exit_code] {
    std::fprintf(stderr,
                 "parallax demo: the visual-odometry pipeline is not implemented yet (tracking, "
                 "depth and the System are open issues). Available now: parallax synth, eval "
                 "and info.\n");
    *exit_code = 2;
  });
}

}  // namespace parallax::cli
