// `relight replay` puts the camera's look on the virtual layer: a synthetic sequence whose colour
// camera blurs and adds noise of known amounts (relight synth --color-blur/--color-noise) is
// replayed with the pebble; the report measures the camera's blur and noise, and the pebble's
// pixels carry that noise (colormap/camera_look.h, render/dir/camera_look_stage.h).
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "cli.h"
#include "relight/core/atomic_file.h"
#include "relight/core/image_io.h"
#include "temp_dir.h"

namespace relight::app {
namespace {

using cli_test::expect_one_line_error;
using cli_test::relight;

const std::filesystem::path kData = RELIGHT_TEST_DATA;
constexpr double kBlur = 1.5, kNoiseFloor = 0.5, kNoiseGain = 0.04;

double true_noise(double code) { return std::sqrt(kNoiseFloor + kNoiseGain * code); }

const std::filesystem::path& camera_sequence() {
  return cli_test::synthetic_sequence("--frames 3 --size 320x240 --trajectory static --color-blur 1.5 --color-noise " +
                                      std::to_string(kNoiseFloor) + "," + std::to_string(kNoiseGain));
}

test::CommandResult replay(const std::filesystem::path& out, const std::string& extra) {
  return relight("replay --quiet " + camera_sequence().string() + " --object " +
                 (kData / "models" / "glossy_pebble.gltf").string() + " --no-video --buffers --colormap none --out " +
                 out.string() + " " + extra);
}

TEST(CameraLookCli, TheReportMeasuresTheCamerasBlurAndNoise) {
  test::TempDir dir;
  const auto result = replay(dir.path() / "look", "");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto report = nlohmann::json::parse(read_text_file(dir.path() / "look" / "report.json"));
  ASSERT_TRUE(report.contains("camera_look")) << report.dump();
  const auto& look = report["camera_look"];
  EXPECT_EQ(look["artefacts"], "all");
  EXPECT_EQ(look["frames"], 3);
  EXPECT_NEAR(look["blur_sigma_px"].get<double>(), kBlur, 0.2 * kBlur) << look.dump();
  int bands = 0;
  for (const auto& band : look["noise"]) {
    if (band["samples"].get<int>() == 0) continue;
    ++bands;
    const double expected = true_noise(band["code"].get<double>());
    for (const auto& sigma : band["sigma"]) EXPECT_NEAR(sigma.get<double>(), expected, 0.25 * expected) << band.dump();
  }
  EXPECT_GE(bands, 3) << look.dump();
  EXPECT_EQ(look["frames_with_motion"], 2) << "a static camera: a motion field of length 0 from frame 1 on";
  EXPECT_LT(look["max_motion_px"].get<double>(), 0.01);
}

/// Whether all pixels within `reach` of (r, c) are covered (or, with `covered` false, none is).
bool all_within(const ColorImage& coverage, int r, int c, int reach, bool covered) {
  for (int i = -reach; i <= reach; ++i)
    for (int j = -reach; j <= reach; ++j) {
      if (!coverage.in_bounds(r + i, c + j)) return false;
      if ((coverage(r + i, c + j).r == 255) != covered) return false;
    }
  return true;
}

TEST(CameraLookCli, ThePebbleCarriesTheCamerasNoiseAndBlurAndNoneKeepsItAsRendered) {
  test::TempDir dir;
  ASSERT_EQ(replay(dir.path() / "noise", "--camera-artefacts noise").exit_code, 0);
  ASSERT_EQ(replay(dir.path() / "blur", "--camera-artefacts blur").exit_code, 0);
  ASSERT_EQ(replay(dir.path() / "sharp", "--camera-artefacts none").exit_code, 0);
  const auto frames = [&](const char* run, const char* suffix) {
    return read_color(dir.path() / run / "frames" / (std::string("000002") + suffix));
  };
  const ColorImage noisy = frames("noise", "_composite.png"), blurred = frames("blur", "_composite.png");
  const ColorImage sharp = frames("sharp", "_composite.png");
  const ColorImage coverage = frames("sharp", "_virtual_coverage.png");
  // Inside the pebble the difference of the noise run and the plain one is the added noise.
  double sum = 0, squares = 0, expected = 0;
  int n = 0;
  for (int r = 0; r < sharp.height(); ++r)
    for (int c = 0; c < sharp.width(); ++c) {
      if (!all_within(coverage, r, c, 1, true)) continue;
      const double d = double(noisy(r, c).g) - double(sharp(r, c).g);
      sum += d;
      squares += d * d;
      expected += true_noise(sharp(r, c).g);
      ++n;
    }
  ASSERT_GT(n, 100) << "the pebble covers the middle of the image";
  const double sd = std::sqrt(squares / n - (sum / n) * (sum / n));
  EXPECT_NEAR(sd, expected / n, 0.35 * expected / n);
  // Across the pebble's outline (pixels with both covered and uncovered pixels within 2 px) the
  // blurred composite's gradient is much weaker than the rendered one's.
  const auto gradient_energy = [&](const ColorImage& image) {
    double energy = 0;
    for (int r = 2; r < image.height() - 2; ++r)
      for (int c = 2; c < image.width() - 2; ++c) {
        if (all_within(coverage, r, c, 2, true) || all_within(coverage, r, c, 2, false)) continue;
        const double gx = double(image(r, c + 1).g) - image(r, c - 1).g,
                     gy = double(image(r + 1, c).g) - image(r - 1, c).g;
        energy += gx * gx + gy * gy;
      }
    return energy;
  };
  EXPECT_LT(gradient_energy(blurred), 0.6 * gradient_energy(sharp));
  // Without artefacts the report has no camera_look and the graph no stage for it.
  const auto report = nlohmann::json::parse(read_text_file(dir.path() / "sharp" / "report.json"));
  EXPECT_FALSE(report.contains("camera_look"));
  // report.html shows the pebble as rendered beside it with the camera's look (two close-ups).
  const std::string html = read_text_file(dir.path() / "blur" / "report.html");
  EXPECT_NE(html.find("<h2>Camera look (frame"), std::string::npos);
  std::size_t close_ups = 0;
  for (std::size_t at = html.find("data:image/png;base64,"); at != std::string::npos;
       at = html.find("data:image/png;base64,", at + 1))
    ++close_ups;
  EXPECT_EQ(close_ups, 2u);
  EXPECT_EQ(read_text_file(dir.path() / "sharp" / "report.html").find("<h2>Camera look"), std::string::npos);
}

// --composite multiplicative through replay: the report says which rule ran; the two rules agree
// wherever the virtual object changes nothing, and both darken its shadow.
TEST(CameraLookCli, TheCompositeRuleReachesTheGraphAndTheReport) {
  test::TempDir dir;
  ASSERT_EQ(replay(dir.path() / "add", "--camera-artefacts none").exit_code, 0);
  ASSERT_EQ(replay(dir.path() / "mul", "--camera-artefacts none --composite multiplicative").exit_code, 0);
  const auto rule = [&](const char* run) {
    return nlohmann::json::parse(read_text_file(dir.path() / run / "report.json"))["composite"]["rule"];
  };
  EXPECT_EQ(rule("add"), "additive");
  EXPECT_EQ(rule("mul"), "multiplicative");
  const auto frames = [&](const char* run, const char* suffix) {
    return read_color(dir.path() / run / "frames" / (std::string("000002") + suffix));
  };
  const ColorImage add = frames("add", "_composite.png"), mul = frames("mul", "_composite.png");
  const ColorImage camera = frames("add", "_color.png"), coverage = frames("add", "_virtual_coverage.png");
  int unchanged = 0, same = 0, darker_both = 0, shadow = 0;
  for (int r = 0; r < camera.height(); ++r)
    for (int c = 0; c < camera.width(); ++c) {
      if (coverage(r, c).r != 0) continue;
      const int cam = camera(r, c).g, a = add(r, c).g, m = mul(r, c).g;
      if (a == cam) {
        ++unchanged;
        same += std::abs(m - cam) <= 1;
      }
      if (a < cam - 10) {
        ++shadow;
        darker_both += m < cam - 5;
      }
    }
  ASSERT_GT(unchanged, camera.width() * camera.height() / 2);
  EXPECT_GT(same, unchanged * 99 / 100);
  ASSERT_GT(shadow, 20) << "the pebble's shadow";
  EXPECT_GT(darker_both, shadow * 9 / 10);
}

// After the first frames the blur and the noise are measured on alternate frames (half their
// cost), and the carried-over estimates still match the camera.
TEST(CameraLookCli, BlurAndNoiseAreMeasuredOnAlternateFramesAfterTheFirstEight) {
  const auto& sequence = cli_test::synthetic_sequence(
      "--frames 12 --size 320x240 --trajectory static --no-gt --color-blur 1.5 --color-noise " +
      std::to_string(kNoiseFloor) + "," + std::to_string(kNoiseGain));
  test::TempDir dir;
  const auto result = relight("replay --quiet " + sequence.string() + " --object " +
                              (kData / "models" / "glossy_pebble.gltf").string() +
                              " --no-video --no-frames --colormap none --out " + (dir.path() / "look").string());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto look = nlohmann::json::parse(read_text_file(dir.path() / "look" / "report.json"))["camera_look"];
  EXPECT_EQ(look["frames"], 12);
  // With no frame images the BRDF preview is made only for report.html's four contact-sheet
  // frames, and each of those rows shows it as a picture.
  const std::string html = read_text_file(dir.path() / "look" / "report.html");
  std::size_t previews = 0;
  for (std::size_t at = html.find("alt=\"brdf_preview frame "); at != std::string::npos;
       at = html.find("alt=\"brdf_preview frame ", at + 1)) {
    ++previews;
    const std::size_t source = html.find("src=\"data:image/jpeg;base64,", at);
    EXPECT_EQ(html.compare(source + 28, 4, "/9j/"), 0) << "a JPEG";
  }
  EXPECT_EQ(previews, 4u);
  EXPECT_EQ(look["blur_estimates"], 10) << "8 frames with both, then every second one";
  EXPECT_EQ(look["noise_estimates"], 10);
  EXPECT_NEAR(look["blur_sigma_px"].get<double>(), kBlur, 0.2 * kBlur) << look.dump();
  for (const auto& band : look["noise"]) {
    if (band["samples"].get<int>() == 0) continue;
    const double expected = true_noise(band["code"].get<double>());
    for (const auto& sigma : band["sigma"]) EXPECT_NEAR(sigma.get<double>(), expected, 0.25 * expected) << band.dump();
  }
}

TEST(CameraLookCli, AnUnknownArtefactIsOneLine) {
  test::TempDir dir;
  expect_one_line_error(replay(dir.path() / "bad", "--camera-artefacts blur,grain"), 2);
}

}  // namespace
}  // namespace relight::app
