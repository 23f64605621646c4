// The colour-mapped differential composite: camera pixels without virtual content stay bit for
// bit, covered pixels show the mapped virtual radiance itself (the real texture behind a virtual
// object does not show through), and on the synthetic camera it reaches the colour goal.
#include "relight/render/dir/mapped_composite_stage.h"

#include <gtest/gtest.h>

#include "colormap/colormap_test_scene.h"
#include "relight/colormap/color_space.h"
#include "relight/core/error.h"
#include "relight/render/dir/composite.h"

namespace relight::render {
namespace {

CoverageImage coverage_of(const Mask& mask) {
  CoverageImage coverage(mask.width(), mask.height());
  for (std::size_t i = 0; i < mask.size(); ++i) coverage.pixels()[i] = mask.pixels()[i] ? 1.f : 0.f;
  return coverage;
}

TEST(MappedComposite, CoveredPixelsShowTheMappedObjectAndOthersTheCameraPlusDelta) {
  const int w = 4, h = 1;
  ColorImage camera(w, h, Rgb8{200, 40, 40});  // a red real texture the object hides at pixel 1
  RadianceImage delta(w, h), real_virtual(w, h, Float3{0.1f, 0.2f, 0.3f});
  CoverageImage coverage(w, h, 0.f);
  coverage(0, 1) = 1.f;
  coverage(0, 2) = 0.5f;
  delta(0, 1) = delta(0, 2) = delta(0, 3) = Float3{-0.05f, 0.f, 0.f};  // e.g. a virtual shadow
  colormap::ColorMapping gain = colormap::ColorMapping::of_matrix(colormap::identity_color_matrix() * 2.0, {});
  const ColorImage out = mapped_differential_composite(camera, delta, real_virtual, real_virtual, coverage, gain);
  EXPECT_EQ(out(0, 0), camera(0, 0));  // nothing virtual: bit for bit
  const Float3 object = gain(real_virtual(0, 1));
  EXPECT_EQ(out(0, 1), colormap::encode_srgb8(object));  // the red texture does not show through
  const Float3 background = colormap::decode_srgb8(camera(0, 2)) + delta(0, 2);
  EXPECT_EQ(out(0, 2), colormap::encode_srgb8(0.5f * object + 0.5f * background));
  EXPECT_EQ(out(0, 3), colormap::encode_srgb8(colormap::decode_srgb8(camera(0, 3)) + delta(0, 3)));
  EXPECT_THROW(
      (void)mapped_differential_composite(camera, RadianceImage(2, 2), real_virtual, real_virtual, coverage, gain),
      Error);
}

TEST(MappedComposite, StatisticsMappingReachesTheColourGoalOnTheSyntheticCamera) {
  const auto& triple = colormap::test::orange_triple();
  const Mask object = colormap::virtual_mask(triple.real, triple.real_virtual);
  RadianceImage delta;
  const auto transfer = colormap::statistics_color_map(triple.real, triple.real_virtual, triple.camera, {}, delta);
  const ColorImage mapped =
      mapped_differential_composite(triple.camera, delta, triple.real_virtual, triple.real, coverage_of(object),
                                    colormap::ColorMapping::of_statistics(transfer, {}));
  const ColorImage unmapped = differential_composite(triple.camera, triple.real_virtual, triple.real,
                                                     coverage_of(object), {});
  const double before = truth::mean_delta_e(unmapped, triple.truth, object);
  const double after = truth::mean_delta_e(mapped, triple.truth, object);
  EXPECT_GT(before, 5.0);  // 5.41 measured
  EXPECT_LT(after, 3.0) << "before " << before;
}

}  // namespace
}  // namespace relight::render
