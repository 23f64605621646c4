// Highlight removal (highlight.h): the HSI rule, the disk dilation, the ring-search fill, and on
// the synthetic scene: the glossy objects' highlights are masked, matte coloured objects are not.
#include "relight/brdf/highlight.h"

#include <gtest/gtest.h>

#include <cstdio>

#include "brdf_test_scene.h"

namespace relight::brdf {
namespace {

int count(const Mask& mask) {
  int n = 0;
  for (auto v : mask.pixels()) n += v != 0;
  return n;
}

TEST(Highlight, HsiRuleNeedsBrightAndUnsaturated) {
  EXPECT_TRUE(is_highlight({255, 255, 255}));
  EXPECT_TRUE(is_highlight({240, 235, 230}));   // I = 0.92, S = 0.02
  EXPECT_FALSE(is_highlight({200, 200, 200}));  // I = 0.78
  EXPECT_FALSE(is_highlight({255, 255, 180}));  // I = 0.90, S = 0.22
  EXPECT_FALSE(is_highlight({0, 0, 0}));
}

TEST(Highlight, DiskDilationOfOnePixelHasTheLatticeDiskArea) {
  Mask mask(21, 21);
  mask(10, 10) = 1;
  Mask out;
  dilate_disk(mask, 4, out);
  EXPECT_EQ(count(out), 49);  // lattice points with dx^2 + dy^2 <= 16
  EXPECT_EQ(out(10, 14), 1);
  EXPECT_EQ(out(13, 13), 0);  // 18 > 16
  EXPECT_EQ(out(12, 13), 1);  // 13 <= 16
  // Near the border the disk is clipped, not wrapped.
  Mask corner(8, 8);
  corner(0, 0) = 1;
  dilate_disk(corner, 4, out);
  EXPECT_EQ(count(out), 17);  // the quarter disk including its axes
}

TEST(Highlight, FillTakesTheNearestUnmaskedColour) {
  // A white 3x3 block on a left-red / right-blue background: the dilated block is painted from
  // the nearest side.
  ColorImage image(21, 11, Rgb8{200, 0, 0});
  for (int r = 0; r < 11; ++r) {
    for (int c = 11; c < 21; ++c) image(r, c) = {0, 0, 200};
  }
  for (int r = 4; r <= 6; ++r) {
    for (int c = 9; c <= 11; ++c) image(r, c) = {255, 255, 255};
  }
  ColorImage cleaned;
  Mask mask;
  remove_highlights(image, {}, cleaned, mask);
  EXPECT_EQ(mask(5, 10), 1);
  EXPECT_EQ(mask(5, 15), 1);   // 4 px right of the block
  EXPECT_EQ(mask(5, 16), 0);
  EXPECT_EQ(cleaned(5, 16), (Rgb8{0, 0, 200}));
  EXPECT_EQ(cleaned(5, 15), (Rgb8{0, 0, 200}));  // nearest unmasked: (5, 16)
  EXPECT_EQ(cleaned(5, 5), (Rgb8{200, 0, 0}));   // (5, 4) is unmasked
  for (const Rgb8 c : cleaned.pixels()) EXPECT_NE(c, (Rgb8{255, 255, 255}));
}

TEST(Highlight, SyntheticSceneHighlightsAreMaskedAndMatteColoursAreNot) {
  const test::BrdfScene& s = test::brdf_scene();
  ColorImage cleaned;
  Mask mask;
  remove_highlights(s.color, {}, cleaned, mask);
  // Ground-truth highlight: the specular radiance alone saturates the camera (>= 1 in every
  // channel at exposure 1), i.e. the pixel shows the light's colour, not the material's.
  int truth = 0, found = 0, glossy_blue_truth = 0;
  const int blue = test::material_id(s.scene, "glossy_blue");
  const int black = test::material_id(s.scene, "tag_black");
  int matte_masked = 0, matte = 0;
  for (int r = 0; r < s.intrinsics.height; ++r) {
    for (int c = 0; c < s.intrinsics.width; ++c) {
      const int id = s.truth.material(r, c);
      const Float3 spec = s.specular(r, c);
      if (id != 0 && std::min({spec.x, spec.y, spec.z}) >= 1.f) {
        ++truth;
        found += mask(r, c);
        glossy_blue_truth += id == blue;
      }
      if (id == 0) continue;
      const synth::Material& m = s.scene.materials[static_cast<std::size_t>(id - 1)];
      const bool white = m.kd.minCoeff() >= 0.6 && m.kd.maxCoeff() - m.kd.minCoeff() <= 0.05;
      if (m.ks == 0.0 && !white) {
        ++matte;
        matte_masked += mask(r, c);
      }
    }
  }
  std::printf("highlight: %d ground-truth pixels (%d on the glossy sphere), %d masked; mask %d px; matte %d px (%d masked)\n",
              truth, glossy_blue_truth, found, count(mask), matte, matte_masked);
  ASSERT_GT(glossy_blue_truth, 20);
  EXPECT_GE(found, 0.95 * truth);
  EXPECT_GT(matte, 500);
  EXPECT_EQ(matte_masked, 0);
  (void)black;
}

}  // namespace
}  // namespace relight::brdf
