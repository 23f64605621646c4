// relight: mixed-reality relighting from RGB-D. Subcommands: synth, replay, graph.
// Exit codes: 0 success, 1 bad input or run-time failure (one line on stderr), 2 usage error (one
// line), 130 replay interrupted (outputs finalised); README "Exit codes and errors".
#include <CLI/CLI.hpp>
#include <algorithm>
#include <exception>
#include <iostream>

#include "commands.h"
#include "relight/core/allocator_tuning.h"
#include "relight/core/error.h"

namespace {

// CLI11 words config problems for INI files and reports them without the file; say both for our
// JSON config.
std::string config_problem(const CLI::App& app, const CLI::ParseError& e) {
  std::string what = dynamic_cast<const CLI::FileError*>(&e) ? "cannot be read" : e.what();
  const std::string ini_prefix = "INI was not able to parse ";
  if (what.rfind(ini_prefix, 0) == 0) {
    std::string key = what.substr(ini_prefix.size());
    for (const CLI::App* command : app.get_subcommands()) {
      if (key.rfind(command->get_name() + ".", 0) == 0) key.erase(0, command->get_name().size() + 1);
    }
    what = "unknown key '" + key + "'";
  }
  const CLI::Option* config = app.get_config_ptr();
  const std::string file = config && !config->results().empty() ? config->results().front() + ": " : "";
  return "--config " + file + what;
}

// One line, like every other relight error; the usage text is one --help away.
std::string usage_problem(const CLI::App& app, const CLI::ParseError& e) {
  std::string line = e.what();
  std::replace(line.begin(), line.end(), '\n', ' ');
  std::string command = "relight";
  for (const CLI::App* selected : app.get_subcommands()) command += " " + selected->get_name();
  return line + " (" + command + " --help lists the options)";
}

}  // namespace

int main(int argc, char** argv) {
  relight::keep_freed_memory_for_reuse();
  CLI::App app{"relight: reconstruct a real scene from RGB-D, estimate its light and materials,\n"
               "and render virtual objects into it with differential instant radiosity."};
  app.require_subcommand(1);
  app.set_version_flag("--version", "relight 0.1.0");
  relight::app::register_commands(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    const bool from_config = dynamic_cast<const CLI::ConfigError*>(&e) || dynamic_cast<const CLI::FileError*>(&e);
    std::cerr << "relight: error: " << (from_config ? config_problem(app, e) : usage_problem(app, e)) << "\n";
    return 2;
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
