// `relight lights` as users run it: a real probe in, lights.json and a preview out; bad input
// gives one line and a non-zero exit.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "relight/core/atomic_file.h"
#include "relight/core/image_io.h"
#include "run_command.h"
#include "temp_dir.h"

namespace relight::app {
namespace {

const std::string kRelight = RELIGHT_BIN;
const std::filesystem::path kProbe = std::filesystem::path(RELIGHT_TEST_DATA) / "probes" / "grace_latlong.hdr";

TEST(LightsCli, RealProbeGivesTheRequestedLightsAndAPreview) {
  test::TempDir dir;
  const auto json_file = dir.path() / "lights.json";
  const auto preview = dir.path() / "lights.png";
  const auto result = test::run_command(kRelight + " lights " + kProbe.string() + " --n 32 --out " +
                                        json_file.string() + " --preview " + preview.string());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto json = nlohmann::json::parse(read_text_file(json_file));
  const std::string dump = json.dump();
  ASSERT_TRUE(json.contains("lights")) << dump.substr(0, 300);
  EXPECT_EQ(json["lights"].size(), 32u);
  for (const auto& light : json["lights"]) {
    ASSERT_TRUE(light.contains("direction")) << light.dump();
    const auto& d = light["direction"];
    const double norm = std::sqrt(d[0].get<double>() * d[0].get<double>() + d[1].get<double>() * d[1].get<double>() +
                                  d[2].get<double>() * d[2].get<double>());
    EXPECT_NEAR(norm, 1.0, 1e-6);
  }
  const ColorImage picture = read_color(preview);
  EXPECT_GT(picture.width(), 0);
}

TEST(LightsCli, BadInputIsOneLineAndNonZero) {
  test::TempDir dir;
  const auto missing = test::run_command(kRelight + " lights " + (dir.path() / "none.hdr").string() + " --out " +
                                         (dir.path() / "l.json").string());
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_EQ(missing.err.rfind("relight: error: ", 0), 0u) << missing.err;
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "l.json"));
  const auto bad_method = test::run_command(kRelight + " lights " + kProbe.string() + " --method magic --out " +
                                            (dir.path() / "l.json").string());
  EXPECT_EQ(bad_method.exit_code, 2);
}

}  // namespace
}  // namespace relight::app
