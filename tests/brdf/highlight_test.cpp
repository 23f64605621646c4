// Highlight removal (highlight.h): the HSI rule, the disk dilation, the ring-search fill, and on
// the synthetic scene: the glossy objects' highlights are masked, matte coloured objects are not.
#include "relight/brdf/highlight.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>

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

// The fill's rule (highlight.h step 4) searched ring by ring, as written: the first Chebyshev
// ring around (r, c) that holds an unmasked pixel, its nearest by Euclidean distance, the first
// in row-major order on ties; beyond `radius` the pixel keeps its colour.
Rgb8 fill_by_rule(const ColorImage& color, const Mask& mask, int r, int c, int radius) {
  for (int ring = 1; ring <= radius; ++ring) {
    int best = -1;
    Rgb8 best_color{};
    for (int rr = r - ring; rr <= r + ring; ++rr)
      for (int cc = c - ring; cc <= c + ring; ++cc) {
        if (std::max(std::abs(rr - r), std::abs(cc - c)) != ring || rr < 0 || cc < 0 || rr >= color.height() ||
            cc >= color.width() || mask(rr, cc))
          continue;
        const int d2 = (rr - r) * (rr - r) + (cc - c) * (cc - c);
        if (best < 0 || d2 < best) {
          best = d2;
          best_color = color(rr, cc);
        }
      }
    if (best >= 0) return best_color;
  }
  return color(r, c);
}

// Large white regions (an overexposed white desk is masked over whole regions, far from any
// unmasked pixel): every masked pixel takes the colour the rule gives, up to the search radius
// and beyond it.
TEST(Highlight, FillOfLargeRegionsFollowsTheRingRule) {
  ColorImage image(96, 64);
  for (int r = 0; r < 64; ++r)
    for (int c = 0; c < 96; ++c)
      image(r, c) = {static_cast<std::uint8_t>(40 + c), static_cast<std::uint8_t>(30 + 2 * r),
                     static_cast<std::uint8_t>((7 * r + 13 * c) % 200)};
  for (int r = 6; r < 58; ++r)  // a white 52 x 60 block, an L-shaped one at the right edge
    for (int c = 10; c < 70; ++c) image(r, c) = {250, 250, 248};
  for (int r = 0; r < 64; ++r)
    for (int c = 80; c < 96; ++c)
      if (r < 20 || c > 88) image(r, c) = {255, 255, 255};
  HighlightOptions options;
  options.fill_radius_max = 20;  // the block's centre is 26 px from its edge: kept
  ColorImage cleaned;
  Mask mask;
  remove_highlights(image, options, cleaned, mask);
  int masked = 0, kept = 0;
  for (int r = 0; r < 64; ++r)
    for (int c = 0; c < 96; ++c) {
      if (!mask(r, c)) {
        EXPECT_EQ(cleaned(r, c), image(r, c));
        continue;
      }
      ++masked;
      const Rgb8 expected = fill_by_rule(image, mask, r, c, options.fill_radius_max);
      kept += expected == image(r, c);
      ASSERT_EQ(cleaned(r, c), expected) << r << "," << c;
    }
  EXPECT_GT(masked, 3000);
  EXPECT_GT(kept, 50) << "pixels beyond the search radius keep their colour";
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
