#pragma once
// Subcommands of the `parallax` executable; each registers itself on the CLI11 app and
// writes its exit status into *exit_code when it runs (docs/cli.md).

#include <CLI/CLI.hpp>

namespace parallax::cli {

void AddBenchCommand(CLI::App& app, int* exit_code);
void AddDemoCommand(CLI::App& app, int* exit_code);
void AddEvalCommand(CLI::App& app, int* exit_code);
void AddFramesCommand(CLI::App& app, int* exit_code);
void AddInfoCommand(CLI::App& app, int* exit_code);
void AddPosegraphCommand(CLI::App& app, int* exit_code);
void AddRunCommand(CLI::App& app, int* exit_code);
void AddSynthCommand(CLI::App& app, int* exit_code);
void AddVocabularyCommand(CLI::App& app, int* exit_code);

}  // namespace parallax::cli
