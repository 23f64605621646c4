// `relight replay --tone-map`: on a high-dynamic-range synthetic frame (the glossy pebble's
// highlight several times the camera's clipping level, the camera's own image unclipped) the
// exposure clamp flattens the highlight into a plateau of equal pixels, in the composite and the
// colour-mapped composite alike; Reinhard's adapted operator rolls it off (colormap/tone_map.h).
#include <gtest/gtest.h>

#include <algorithm>
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

const std::filesystem::path& sequence() {
  return cli_test::synthetic_sequence("--frames 3 --size 320x240 --trajectory static");
}

test::CommandResult replay(const std::filesystem::path& out, const std::string& extra) {
  return relight("replay --quiet " + sequence().string() + " --object " +
                 (kData / "models" / "glossy_pebble.gltf").string() +
                 " --no-video --buffers --camera-artefacts none --out " + out.string() + " " + extra);
}

struct Highlight {
  int brightest = 0;  ///< the pebble's largest channel value
  int plateau = 0;    ///< pebble pixels within 1 code of it: a clipped highlight is a flat patch
  int pixels = 0;
};

Highlight highlight(const ColorImage& image, const ColorImage& coverage) {
  Highlight h;
  const auto value = [&](int r, int c) { return int(std::max({image(r, c).r, image(r, c).g, image(r, c).b})); };
  for (int r = 0; r < image.height(); ++r)
    for (int c = 0; c < image.width(); ++c)
      if (coverage(r, c).r == 255) h.brightest = std::max(h.brightest, value(r, c)), ++h.pixels;
  for (int r = 0; r < image.height(); ++r)
    for (int c = 0; c < image.width(); ++c)
      if (coverage(r, c).r == 255 && value(r, c) >= h.brightest - 1) ++h.plateau;
  return h;
}

TEST(ToneMapCli, ReinhardRollsOffTheHighlightThatTheExposureClampFlattens) {
  test::TempDir dir;
  ASSERT_EQ(replay(dir.path() / "exposure", "--tone-map exposure").exit_code, 0);
  const auto result = replay(dir.path() / "reinhard", "--tone-map reinhard");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto frame = [&](const char* run, const char* suffix) {
    return read_color(dir.path() / run / "frames" / (std::string("000002") + suffix));
  };
  const ColorImage camera = frame("exposure", "_color.png"), coverage = frame("exposure", "_virtual_coverage.png");
  int clipped = 0;
  for (const Rgb8& p : camera.pixels()) clipped += std::max({p.r, p.g, p.b}) == 255;
  ASSERT_LT(clipped, static_cast<int>(camera.size()) / 200) << "the camera's image is not clipped";

  const auto report = nlohmann::json::parse(read_text_file(dir.path() / "reinhard" / "report.json"));
  const auto& tm = report["tone_map"];
  EXPECT_EQ(tm["operator"], "reinhard") << tm.dump();
  ASSERT_GT(tm["white"].get<double>(), 3.0) << "an HDR frame: the highlight is several times the clip level";
  EXPECT_NEAR(tm["scale"].get<double>(), 0.18 / tm["log_average_luminance"].get<double>(), 1e-4) << tm.dump();
  EXPECT_EQ(nlohmann::json::parse(read_text_file(dir.path() / "exposure" / "report.json"))["tone_map"]["operator"],
            "exposure");

  for (const char* suffix : {"_composite.png", "_composite_mapped.png"}) {
    SCOPED_TRACE(suffix);
    const Highlight clamp = highlight(frame("exposure", suffix), coverage);
    const Highlight rolled = highlight(frame("reinhard", suffix), coverage);
    ASSERT_GT(clamp.pixels, 200) << "the pebble is in view";
    EXPECT_GE(clamp.plateau, 15) << "the exposure clamp clips the highlight flat";
    // Measured: the clamp flattens 29 of 595 pebble pixels within a code of 255. Reinhard left at
    // most 8 at its peak in both composites until the real layer's shadow test tolerated the depth
    // noise (shadow_maps.h); since, the colour-mapped one (whose camera fit follows the real
    // surfaces' light) has 12.
    EXPECT_LE(rolled.plateau, std::max(8, clamp.plateau / 2))
        << "Reinhard leaves at most its peak at the top (the clamp: " << clamp.plateau << " of " << clamp.pixels
        << " pixels within a code of " << clamp.brightest << ")";
    EXPECT_GE(rolled.brightest, 200) << "and the highlight stays a highlight";
  }
}

// The key follows the real light through the product: a sequence whose key light switches off
// at frame 4 (relight synth --light-animation switch-off; the lights follow its probe stream).
// With a short adaptation time the last frame's log-average luminance is that of the dark frames
// on their own; with a long one it is still near the lit frames'.
TEST(ToneMapCli, TheKeyFollowsALightSwitchedOffWithinTheAdaptationTime) {
  const auto& switched = cli_test::synthetic_sequence(
      "--frames 12 --size 320x240 --trajectory static --no-gt --light-animation switch-off --light-event-frame 4");
  test::TempDir dir;
  const auto log_average = [&](const std::string& name, const std::string& extra) {
    const auto out = dir.path() / name;
    const auto result = relight(
        "replay --quiet " + switched.string() + " --object " + (kData / "models" / "glossy_pebble.gltf").string() +
        " --no-video --no-frames --camera-artefacts none --tone-map reinhard --out " + out.string() + " " + extra);
    EXPECT_EQ(result.exit_code, 0) << result.err;
    return nlohmann::json::parse(read_text_file(out / "report.json"))["tone_map"]["log_average_luminance"]
        .get<double>();
  };
  const double lit = log_average("lit", "--frames 0:4");
  const double dark = log_average("dark", "--frames 6:12 --tone-adaptation 0.02");
  ASSERT_LT(dark, 0.9 * lit) << "the switch darkens the scene";
  EXPECT_NEAR(log_average("fast", "--tone-adaptation 0.02"), dark, 0.01 * dark);
  const double slow = log_average("slow", "--tone-adaptation 20");
  EXPECT_NEAR(slow, lit, 0.05 * lit);
  EXPECT_GT(slow, 1.1 * dark);
}

TEST(ToneMapCli, AnUnknownOperatorIsOneLine) {
  test::TempDir dir;
  const auto result = replay(dir.path() / "bad", "--tone-map filmic");
  expect_one_line_error(result, 2);
  EXPECT_NE(result.err.find("--tone-map"), std::string::npos) << result.err;
}

}  // namespace
}  // namespace relight::app
