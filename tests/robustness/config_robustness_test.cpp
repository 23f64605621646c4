// Robustness matrix, JSON config files (--config): a usage error, exit 2, one line naming the file
// and what is wrong with it, before anything is written.
#include <gtest/gtest.h>

#include "inputs.h"
#include "outcome_checks.h"

namespace relight::robustness {
namespace {

class ConfigRobustness : public ::testing::Test {
 protected:
  // replay with the config file holding `text`; the run must fail before creating --out.
  RunOutcome replay_with(const std::string& text) {
    write_file_atomically(config, text);
    return run_relight({"replay", "--config", config.string(), "--out", out.string()});
  }
  test::TempDir dir;
  const std::filesystem::path config = dir.path() / "cfg.json";
  const std::filesystem::path out = dir.path() / "out";
};

TEST_F(ConfigRobustness, MalformedJson) {
  const auto run = replay_with("{\"frames\": \"0:2\",");
  expect_clean_error(run, 2, config.string() + ": not valid JSON", out);
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST_F(ConfigRobustness, NotAnObject) {
  expect_clean_error(replay_with("[\"frames\", 2]"), 2, config.string() + ": must hold a JSON object", out);
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST_F(ConfigRobustness, UnknownKey) {
  const auto run = replay_with("{\"frames\": \"0:2\", \"exposure_bias\": 2}");
  expect_clean_error(run, 2, config.string() + ": unknown key 'exposure_bias'", out);
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST_F(ConfigRobustness, ValueOfTheWrongType) {
  const auto run = replay_with("{\"vpls\": \"many\"}");
  expect_clean_error(run, 2, "--vpls", out);
  EXPECT_FALSE(std::filesystem::exists(out));
}

// Found by fuzzing (fuzz/json_config_fuzzer.cpp): a config nested a hundred thousand levels deep
// used to overflow the stack, in the sections (objects) and in the error message quoting a value
// (arrays).
TEST_F(ConfigRobustness, DeeplyNestedSectionsOrValues) {
  constexpr int kDepth = 100000;
  std::string objects;
  for (int i = 0; i < kDepth; ++i) objects += "{\"replay\": ";
  objects += "1" + std::string(kDepth, '}');
  expect_clean_error(replay_with(objects), 2, config.string() + ": sections nest deeper than", out);
  const std::string arrays = "{\"object\": " + std::string(kDepth, '[') + std::string(kDepth, ']') + "}";
  expect_clean_error(replay_with(arrays), 2, config.string() + ": the value of 'object' must be", out);
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST_F(ConfigRobustness, MissingFile) {
  const auto run = run_relight({"replay", "--config", config.string(), "--out", out.string()});
  expect_clean_error(run, 2, config.string() + ": cannot be read", out);
  EXPECT_FALSE(std::filesystem::exists(out));
}

// Another subcommand reads the same config format: the contract holds there too.
TEST_F(ConfigRobustness, UnknownKeyForLights) {
  write_file_atomically(config, std::string_view("{\"n\": 8, \"samples\": 8}"));
  const auto lights = dir.path() / "lights.json";
  const auto run = run_relight({"lights", (kData / "probes" / "grace_latlong.hdr").string(), "--config", config.string(),
                                "--out", lights.string()});
  expect_clean_error(run, 2, config.string() + ": unknown key 'samples'", dir.path());
  EXPECT_FALSE(std::filesystem::exists(lights));
}

}  // namespace
}  // namespace relight::robustness
