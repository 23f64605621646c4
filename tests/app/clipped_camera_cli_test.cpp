// `relight replay` over a camera that clips: a synthetic sequence exposed so that the lit table
// clips (relight synth --exposure 2.2, rendered with the same exposure); the pebble's shadow on
// the clipped table keeps the table's chromaticity - that of the camera's unclipped table pixels
// around it - within 0.02, before and after colour mapping (render/dir/composite.h, the clipped
// camera's reconstruction; brdf/'s clipped pixels take the albedo of their unclipped surface).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "cli.h"
#include "relight/colormap/color_space.h"
#include "relight/core/image_io.h"
#include "temp_dir.h"

namespace relight::app {
namespace {

using cli_test::relight;

const std::filesystem::path kData = RELIGHT_TEST_DATA;

struct Chromaticity {
  double r = 0.0, g = 0.0;
  int pixels = 0;
};

/// Mean rg chromaticity of linear colours over `pixels`, leaving out near-black ones (no hue).
template <class Pixels>
Chromaticity mean_chromaticity(const ColorImage& image, const Pixels& pixels) {
  Chromaticity c;
  for (const auto& [r, col] : pixels) {
    const Float3 v = colormap::decode_srgb8(image(r, col));
    const double sum = double(v.x) + v.y + v.z;
    if (sum < 0.06) continue;
    c.r += v.x / sum, c.g += v.y / sum, ++c.pixels;
  }
  if (c.pixels > 0) c.r /= c.pixels, c.g /= c.pixels;
  return c;
}

TEST(ClippedCameraCli, TheShadowOnAClippedTableKeepsTheTablesChromaticity) {
  const auto& sequence =
      cli_test::synthetic_sequence("--frames 3 --size 320x240 --trajectory static --exposure 2.2 --no-gt");
  test::TempDir dir;
  const auto result = relight(
      "replay --quiet " + sequence.string() + " --object " + (kData / "models" / "glossy_pebble.gltf").string() +
      " --exposure 2.2 --no-video --buffers --camera-artefacts none --out " + (dir.path() / "out").string());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto frame = [&](const char* suffix) {
    return read_color(dir.path() / "out" / "frames" / (std::string("000002") + suffix));
  };
  const ColorImage camera = frame("_color.png"), coverage = frame("_virtual_coverage.png");
  for (const char* suffix : {"_composite.png", "_composite_mapped.png"}) {
    SCOPED_TRACE(suffix);
    const ColorImage composite = frame(suffix);
    std::set<std::pair<int, int>> shadow;
    int clipped = 0, top = camera.height(), bottom = 0, left = camera.width(), right = 0;
    for (int r = 0; r < camera.height(); ++r)
      for (int c = 0; c < camera.width(); ++c) {
        if (coverage(r, c).r != 0 || int(camera(r, c).g) - int(composite(r, c).g) <= 15) continue;
        shadow.insert({r, c});
        clipped += std::max({camera(r, c).r, camera(r, c).g, camera(r, c).b}) >= 250;
        top = std::min(top, r), bottom = std::max(bottom, r), left = std::min(left, c), right = std::max(right, c);
      }
    ASSERT_GT(shadow.size(), 60u) << "the pebble's shadow";
    ASSERT_GT(clipped, static_cast<int>(shadow.size()) * 3 / 4) << "falls on a clipped table";
    // The camera's unclipped pixels around the shadow that the pebble leaves unchanged.
    std::vector<std::pair<int, int>> neighbours;
    for (int r = std::max(0, top - 20); r < std::min(camera.height(), bottom + 20); ++r)
      for (int c = std::max(0, left - 20); c < std::min(camera.width(), right + 20); ++c) {
        if (shadow.contains({r, c}) || coverage(r, c).r != 0) continue;
        if (std::max({camera(r, c).r, camera(r, c).g, camera(r, c).b}) >= 245) continue;
        if (std::abs(int(composite(r, c).g) - int(camera(r, c).g)) > 2) continue;
        neighbours.emplace_back(r, c);
      }
    const Chromaticity in_shadow = mean_chromaticity(composite, shadow);
    const Chromaticity around = mean_chromaticity(camera, neighbours);
    ASSERT_GT(in_shadow.pixels, 40);
    ASSERT_GT(around.pixels, 100);
    EXPECT_NEAR(in_shadow.r, around.r, 0.02);
    EXPECT_NEAR(in_shadow.g, around.g, 0.02);
  }
}

}  // namespace
}  // namespace relight::app
