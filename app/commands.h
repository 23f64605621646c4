#pragma once
// The subcommands of the relight CLI: each registers its options on a CLI11 subcommand and a
// runner invoked after parsing.
#include <CLI/CLI.hpp>

namespace relight::app {

void register_commands(CLI::App& app);
/// Runs the subcommand that was selected on the command line; returns the exit code.
int run_selected(CLI::App& app);

}  // namespace relight::app
