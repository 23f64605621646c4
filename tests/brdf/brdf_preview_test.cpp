// The per-frame BRDF picture: five panels of the camera's size, each showing what it says.
#include "relight/brdf/brdf_preview.h"

#include <gtest/gtest.h>

#include "relight/core/error.h"

namespace relight::brdf {
namespace {

TEST(BrdfPreview, LaysOutCameraMaskKdClustersAndRerender) {
  const int w = 4, h = 3;
  ColorImage color(w, h);
  color(1, 2) = {10, 20, 30};
  Mask highlights(w, h);
  highlights(0, 1) = 1;
  RadianceImage kd(w, h);
  kd(2, 3) = {1.f, 0.f, 0.5f};
  Materials materials;
  materials.ids = LabelImage(w, h);
  materials.ids(1, 0) = 1;
  materials.ids(1, 1) = 2;
  RadianceImage rerender(w, h);
  rerender(2, 2) = {0.214f, 2.f, 0.f};  // sRGB 128, clamped to 255, 0
  const ColorImage preview = brdf_preview(color, highlights, kd, materials, rerender);
  ASSERT_EQ(preview.width(), 5 * w);
  ASSERT_EQ(preview.height(), h);
  EXPECT_EQ(preview(1, 2), (Rgb8{10, 20, 30}));
  EXPECT_EQ(preview(0, w + 1), (Rgb8{255, 255, 255}));
  EXPECT_EQ(preview(0, w + 0), (Rgb8{0, 0, 0}));
  EXPECT_EQ(preview(2, 2 * w + 3), (Rgb8{255, 0, 188}));
  EXPECT_EQ(preview(0, 3 * w), (Rgb8{0, 0, 0})) << "no cluster: black";
  EXPECT_NE(preview(1, 3 * w + 0), preview(1, 3 * w + 1)) << "two clusters, two colours";
  EXPECT_NE(preview(1, 3 * w + 0), (Rgb8{0, 0, 0}));
  const Rgb8 r = preview(2, 4 * w + 2);
  EXPECT_NEAR(r.r, 128, 1);
  EXPECT_EQ(r.g, 255);
  EXPECT_EQ(r.b, 0);
  EXPECT_THROW((void)brdf_preview(color, Mask(w + 1, h), kd, materials, rerender), Error);
}

}  // namespace
}  // namespace relight::brdf
