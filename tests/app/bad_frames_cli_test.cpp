// relight replay on a TUM folder with a missing image: an error naming the file by default, a
// warning naming the frame with --skip-bad-frames.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "relight/core/atomic_file.h"
#include "run_command.h"
#include "temp_dir.h"

namespace relight::app {
namespace {

TEST(ReplayBadFrames, MissingImageFailsOrIsSkippedOnRequest) {
  test::TempDir dir;
  const auto folder = dir.path() / "seq";
  std::filesystem::copy(std::filesystem::path(RELIGHT_TEST_DATA) / "tum_fr1_rpy", folder,
                        std::filesystem::copy_options::recursive);
  std::filesystem::remove(folder / "depth" / "1305031229.564442.png");  // the second frame's depth
  const std::string replay = std::string(RELIGHT_BIN) + " replay --cpu --quiet --no-frames " + folder.string();

  const auto strict = test::run_command(replay + " --out " + (dir.path() / "a").string());
  EXPECT_EQ(strict.exit_code, 1);
  EXPECT_EQ(strict.err.rfind("relight: error: ", 0), 0u) << strict.err;
  EXPECT_NE(strict.err.find("1305031229.564442.png"), std::string::npos) << strict.err;

  const auto lenient = test::run_command(replay + " --skip-bad-frames --out " + (dir.path() / "b").string());
  ASSERT_EQ(lenient.exit_code, 0) << lenient.err;
  EXPECT_NE(lenient.err.find("relight: warning: frame 1 skipped"), std::string::npos) << lenient.err;
  const auto report = nlohmann::json::parse(read_text_file(dir.path() / "b" / "report.json"));
  EXPECT_EQ(report["frames"], 3);
}

}  // namespace
}  // namespace relight::app
