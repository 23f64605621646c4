#pragma once
// Running the relight executable in CLI tests, and the checks every command's errors share.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "run_command.h"

namespace relight::cli_test {

inline CommandResult relight(const std::string& arguments) { return run_command(std::string(RELIGHT_BIN) + " " + arguments); }

/// One line on stderr, "relight: error: ...", and the given exit code.
inline void expect_one_line_error(const CommandResult& result, int exit_code) {
  EXPECT_EQ(result.exit_code, exit_code) << result.err;
  EXPECT_EQ(result.err.rfind("relight: error: ", 0), 0u) << result.err;
  EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
}

}  // namespace relight::cli_test
