// relight: mixed-reality relighting from RGB-D. Subcommands: synth, replay, graph.
// Exit codes: 0 success, 1 bad input or run-time failure (one line on stderr), 2 usage error.
#include <CLI/CLI.hpp>
#include <exception>
#include <iostream>

#include "commands.h"
#include "relight/core/error.h"

int main(int argc, char** argv) {
  CLI::App app{"relight: reconstruct a real scene from RGB-D, estimate its light and materials,\n"
               "and render virtual objects into it with differential instant radiosity."};
  app.require_subcommand(1);
  app.set_version_flag("--version", "relight 0.1.0");
  relight::app::register_commands(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ConfigError& e) {
    // CLI11 words config problems for INI files; say it for our JSON config.
    std::string what = e.what();
    const std::string ini_prefix = "INI was not able to parse ";
    if (what.rfind(ini_prefix, 0) == 0) what = "unknown key '" + what.substr(ini_prefix.size()) + "'";
    std::cerr << "relight: error: --config: " << what << "\n";
    return 2;
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }
  try {
    return relight::app::run_selected(app);
  } catch (const relight::Error& e) {
    std::cerr << "relight: error: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "relight: internal error: " << e.what() << "\n";
    return 1;
  }
}
