#pragma once
// Running the relight executable in CLI tests, and the checks every command's errors share.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "run_command.h"
#include "temp_dir.h"

namespace relight::cli_test {

inline test::CommandResult relight(const std::string& arguments) {
  return test::run_command(std::string(RELIGHT_BIN) + " " + arguments);
}

/// One line on stderr, "relight: error: ...", and the given exit code.
inline void expect_one_line_error(const test::CommandResult& result, int exit_code) {
  EXPECT_EQ(result.exit_code, exit_code) << result.err;
  EXPECT_EQ(result.err.rfind("relight: error: ", 0), 0u) << result.err;
  EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
}

/// The sequence `relight synth --quiet <arguments>` writes, made once per test binary for each
/// argument string and kept until it exits (synthesising costs more than most tests).
inline const std::filesystem::path& synthetic_sequence(const std::string& arguments) {
  static test::TempDir dir;
  static std::map<std::string, std::filesystem::path> made;
  if (const auto found = made.find(arguments); found != made.end()) return found->second;
  const auto path = dir.path() / std::to_string(made.size());
  const auto result = relight("synth --quiet " + arguments + " --out " + path.string());
  EXPECT_EQ(result.exit_code, 0) << result.err;
  return made.emplace(arguments, path).first->second;
}

/// The report.json row of stage `name` exists, says Vulkan and has a GPU time; returns the row.
inline nlohmann::json expect_dispatches_on_the_device(const nlohmann::json& report, const std::string& name) {
  for (const auto& stage : report["stages"]) {
    if (stage["stage"] != name) continue;
    EXPECT_EQ(stage["backend"], "Vulkan") << name;
    EXPECT_GT(stage.value("device_median_ms", 0.0), 0.0) << name << ": " << stage.dump();
    return stage;
  }
  ADD_FAILURE() << "no stage " << name << " in the report";
  return {};
}

}  // namespace relight::cli_test
