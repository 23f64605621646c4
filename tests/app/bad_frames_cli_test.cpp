// relight replay on a TUM folder with a missing image: an error naming the file by default, a
// warning naming the frame with --skip-bad-frames; a frame picture that cannot be written (the
// frame writer's queue writes it while the next frame runs) still ends the run with one line.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

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

TEST(ReplayBadFrames, AFramePictureThatCannotBeWrittenIsOneErrorLine) {
  test::TempDir dir;
  const auto out = dir.path() / "out";
  // Frame 1's colour picture cannot take its name: a folder stands there.
  std::filesystem::create_directories(out / "frames" / "000001_color.png");
  const auto result =
      test::run_command(std::string(RELIGHT_BIN) + " replay --cpu --quiet --no-video " +
                        (std::filesystem::path(RELIGHT_TEST_DATA) / "tum_fr1_rpy").string() + " --out " + out.string());
  EXPECT_EQ(result.exit_code, 1) << result.err;
  EXPECT_EQ(result.err.rfind("relight: error: ", 0), 0u) << result.err;
  EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
  EXPECT_NE(result.err.find("000001_color.png"), std::string::npos) << result.err;
  // Frame 0's pictures were written whole, and no temporary file is left behind.
  EXPECT_GT(std::filesystem::file_size(out / "frames" / "000000_color.png"), 1000u);
  for (const auto& entry : std::filesystem::directory_iterator(out / "frames"))
    EXPECT_EQ(entry.path().filename().string().find(".tmp"), std::string::npos) << entry.path();
}

}  // namespace
}  // namespace relight::app
