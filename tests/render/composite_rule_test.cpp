// The additive and the multiplicative differential composite (composite.h) against the path
// tracer's picture of the mixed scene, where the renderer's real scene matches the camera and
// where it does not (measured lights of the wrong colour: an orange probe over a neutral room).
#include <gtest/gtest.h>

#include <cmath>

#include "relight/colormap/color_space.h"
#include "relight/render/dir/composite.h"
#include "relight/render/dir/dir.h"
#include "test_scenes.h"

namespace relight::render {
namespace {

constexpr int kWidth = 96, kHeight = 72;

/// A white floor and a red virtual cube, a point light to the right of the camera (the cube's
/// shadow falls on the floor in view) and a weaker one to the left (which lights that shadow).
/// `light_colour` tints both lights.
MrScene shadow_scene(const Eigen::Vector3f& light_colour) {
  MrScene scene = test::floor_scene(Eigen::Vector3f::Constant(0.8f), {0.9f, -0.4f, 1.4f}, 1.f);
  scene.lights[0].intensity = 5.f * light_colour;
  MrLight fill = scene.lights[0];
  fill.position = {-1.2f, -0.8f, 1.3f};
  fill.intensity = 2.f * light_colour;
  scene.lights.push_back(fill);
  test::add_virtual_box(scene, synth::Box{{-0.2, -0.2, 0.0}, {0.2, 0.2, 0.4}},
                        test::diffuse({0.9f, 0.1f, 0.1f}, "red"));
  return scene;
}

struct ShadowErrors {
  double chroma = 0.0;  ///< mean |rg chromaticity| difference from the truth over the shadow
  double rmse = 0.0;    ///< 8-bit levels over the shadow
  int pixels = 0;
};

ShadowErrors shadow_errors(const ColorImage& composite, const ColorImage& truth, const ColorImage& camera,
                           const CoverageImage& coverage) {
  ShadowErrors e;
  double squares = 0.0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const Rgb8 t = truth.pixels()[i], c = camera.pixels()[i], o = composite.pixels()[i];
    // The shadow: real pixels the object darkens by more than 20 %.
    if (coverage.pixels()[i] != 0.f || double(t.r) + t.g + t.b > 0.8 * (double(c.r) + c.g + c.b)) continue;
    const auto chroma = [](const Rgb8& p) {
      const double sum = std::max(1.0, double(p.r) + p.g + p.b);
      return std::pair{p.r / sum, p.g / sum};
    };
    const auto [tr, tg] = chroma(t);
    const auto [orr, og] = chroma(o);
    e.chroma += std::abs(orr - tr) + std::abs(og - tg);
    for (const auto& [a, b] : {std::pair{o.r, t.r}, {o.g, t.g}, {o.b, t.b}})
      squares += (double(a) - b) * (double(a) - b);
    ++e.pixels;
  }
  e.chroma /= std::max(1, e.pixels);
  e.rmse = std::sqrt(squares / std::max(1, 3 * e.pixels));
  return e;
}

ColorImage encoded(const RadianceImage& radiance, const colormap::ToneMap& tone_map) {
  ColorImage out(radiance.width(), radiance.height());
  for (std::size_t i = 0; i < out.size(); ++i)
    out.pixels()[i] = colormap::encode_srgb8(colormap::tone_map(radiance.pixels()[i], tone_map));
  return out;
}

TEST(CompositeRule, MultiplicativeKeepsTheShadowsHueWhereTheMeasuredLightIsWrong) {
  const MrCamera camera = test::camera_at({0.3, -1.6, 1.2}, {0, 0, 0.15}, kWidth, kHeight);
  const colormap::ToneMap tone_map{};
  // The truth: the white-lit scene with the cube, as the camera would film it (direct light).
  PathTracerOptions pt;
  pt.max_bounces = 0;
  const MrScene true_scene = shadow_scene({1.f, 1.f, 1.f});
  const DifferentialImages reference = render_reference(true_scene, camera, 64, pt);
  const ColorImage film = encoded(reference.real, tone_map), truth = encoded(reference.real_virtual, tone_map);
  for (const bool wrong_light : {false, true}) {
    // DIR with the lights as measured: right, or orange (1, 0.75, 0.5).
    const MrScene measured = shadow_scene(wrong_light ? Eigen::Vector3f(1.f, 0.75f, 0.5f) : Eigen::Vector3f::Ones());
    GBuffer gbuffer;
    const DifferentialImages dir = render_dir_cpu(measured, camera, {}, {}, &gbuffer);
    CompositeOptions additive, multiplicative;
    multiplicative.rule = CompositeRule::Multiplicative;
    const ShadowErrors add = shadow_errors(
        differential_composite(film, dir.real_virtual, dir.real, dir.virtual_coverage, tone_map, additive), truth, film,
        dir.virtual_coverage);
    const ShadowErrors mul = shadow_errors(
        differential_composite(film, dir.real_virtual, dir.real, dir.virtual_coverage, tone_map, multiplicative), truth,
        film, dir.virtual_coverage);
    ASSERT_GT(add.pixels, 100);
    std::cout << (wrong_light ? "orange" : "right") << " light, shadow (" << add.pixels
              << " px): additive chroma error " << add.chroma << ", RMSE " << add.rmse << "; multiplicative "
              << mul.chroma << ", " << mul.rmse << "\n";
    if (wrong_light) {
      EXPECT_LT(mul.chroma, 0.3 * add.chroma);
      EXPECT_LT(mul.rmse, 0.5 * add.rmse);
      EXPECT_LT(mul.chroma, 0.02);
    } else {
      // Where the render matches the camera the two rules agree (one light: its shadow is a ratio).
      EXPECT_LT(std::abs(mul.rmse - add.rmse), 2.0);
      EXPECT_LT(mul.chroma, 0.02);
      EXPECT_LT(add.chroma, 0.02);
    }
  }
}

// A camera pixel that clipped its red channel (the true value ~1.4) under a virtual shadow that
// halves the light: both rules reconstruct red from the render's chromaticity and halve all
// three channels, so the shadow keeps the surface's hue instead of staying at red 255.
TEST(ClippedCamera, ShadowOverAClippedChannelScalesTheReconstructedValue) {
  const Float3 truth{1.4f, 0.8f, 0.5f};  // what an unclipped camera would record
  const Float3 camera_linear{1.f, truth.y, truth.z};
  ColorImage camera(2, 1, colormap::encode_srgb8(camera_linear));
  const Float3 recorded = colormap::decode_srgb8(camera(0, 0));
  RadianceImage real(2, 1, Float3{0.7f, 0.4f, 0.25f});  // the render: half the truth, same hue
  RadianceImage real_virtual = real;
  real_virtual(0, 1) = 0.5f * real(0, 1);  // pixel 1 lies in the shadow, pixel 0 unchanged
  const CoverageImage coverage(2, 1, 0.f);
  for (const CompositeRule rule : {CompositeRule::Additive, CompositeRule::Multiplicative}) {
    SCOPED_TRACE(static_cast<int>(rule));
    const ColorImage out =
        differential_composite(camera, real_virtual, real, coverage, colormap::ToneMap{}, {.rule = rule});
    EXPECT_EQ(out(0, 0), camera(0, 0)) << "unchanged pixels keep the camera's value";
    const Float3 shadow = colormap::decode_srgb8(out(0, 1));
    // Scale of the render to the camera from the unclipped channels: (0.8 + 0.5) / (0.4 + 0.25).
    const float k = (recorded.y + recorded.z) / 0.65f;
    EXPECT_NEAR(shadow.x, 0.5f * k * 0.7f, 0.01f);
    EXPECT_NEAR(shadow.y, 0.5f * recorded.y, 0.01f);
    EXPECT_NEAR(shadow.z, 0.5f * recorded.z, 0.01f);
    EXPECT_LT(out(0, 1).r, 250);
    // The mapped composite (identity mapping) does the same.
    RadianceImage delta(2, 1);
    delta(0, 1) = real_virtual(0, 1) - real(0, 1);
    const ColorImage mapped = mapped_differential_composite(
        camera, delta, real_virtual, real, coverage,
        colormap::ColorMapping::of_matrix(colormap::identity_color_matrix(), {}), {.rule = rule});
    EXPECT_EQ(mapped(0, 1), out(0, 1));
    EXPECT_EQ(mapped(0, 0), camera(0, 0));
  }
}

}  // namespace
}  // namespace relight::render
