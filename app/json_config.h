#pragma once
// Lets every `relight` subcommand read its options from a JSON file (--config cfg.json) whose
// keys are the long flag names without dashes: {"frames": 30, "out": "X", "quiet": true}.
// Arrays give several values; nested objects address nested subcommands. Unknown keys are an
// error (CLI11 reports them with the key name). Flags given on the command line win.
#include <CLI/CLI.hpp>

namespace relight::app {

class JsonConfig final : public CLI::Config {
 public:
  /// Keys without a section apply to the subcommand selected on `root`'s command line.
  explicit JsonConfig(const CLI::App* root) : root_(root) {}
  std::string to_config(const CLI::App* app, bool default_also, bool write_description,
                        std::string prefix) const override;
  std::vector<CLI::ConfigItem> from_config(std::istream& input) const override;

 private:
  const CLI::App* root_;
};

/// Adds `--config FILE` (JSON) to the main app; subcommands accept it after their name too.
/// CLI11 reads config files on the main app only, after the command line is parsed.
void add_json_config(CLI::App& root);

}  // namespace relight::app
