// Diffuse reflectance (diffuse.h, eq. 4.13) on the synthetic scene with exact normals and lights:
// on directly lit pixels whose radiance is (almost) purely diffuse, k_d is the true albedo to
// within 0.03 in every channel after 8-bit quantisation; shadows and missing geometry are handled
// as documented.
#include "relight/brdf/diffuse.h"

#include <gtest/gtest.h>

#include <cstdio>

#include "brdf_test_scene.h"
#include "relight/brdf/highlight.h"

namespace relight::brdf {
namespace {

struct Errors {
  int pixels = 0;
  int within = 0;
  double worst = 0.0;
};

TEST(Diffuse, RecoversTheAlbedoOnDirectlyLitDiffusePixels) {
  const test::BrdfScene& s = test::brdf_scene();
  ColorImage cleaned;
  Mask highlights;
  remove_highlights(s.color, {}, cleaned, highlights);
  RadianceImage kd;
  Mask valid;
  estimate_diffuse(cleaned, s.positions, s.truth.normals, s.lights, {}, kd, valid);

  Errors matte, lit;
  int background_valid = 0;
  for (int r = 0; r < s.intrinsics.height; ++r) {
    for (int c = 0; c < s.intrinsics.width; ++c) {
      const int id = s.truth.material(r, c);
      if (id == 0) {
        background_valid += valid(r, c);
        continue;
      }
      if (s.shadowed(r, c) || highlights(r, c) || !valid(r, c)) continue;
      const Float3 e = kd(r, c) - s.truth.albedo(r, c);
      const double error = std::max({std::abs(e.x), std::abs(e.y), std::abs(e.z)});
      const Float3 spec = s.specular(r, c), radiance = s.truth.radiance(r, c);
      // "Purely diffuse": the specular part is below 1 % of the radiance (or the camera clips).
      const bool diffuse = spec.x <= 0.01f * radiance.x && std::max({radiance.x, radiance.y, radiance.z}) < 1.f;
      const synth::Material& m = s.scene.materials[static_cast<std::size_t>(id - 1)];
      for (Errors* errors : {m.ks == 0.0 ? &matte : nullptr, diffuse ? &lit : nullptr}) {
        if (!errors) continue;
        ++errors->pixels;
        errors->within += error <= 0.03;
        errors->worst = std::max(errors->worst, error);
      }
    }
  }
  std::printf("diffuse: matte %d px (worst %.4f), diffuse-lit %d px (%.2f %% within 0.03, worst %.4f)\n", matte.pixels,
              matte.worst, lit.pixels, 100.0 * lit.within / std::max(1, lit.pixels), lit.worst);
  EXPECT_EQ(background_valid, 0);
  ASSERT_GT(matte.pixels, 10000);
  EXPECT_LE(matte.worst, 0.03);
  ASSERT_GT(lit.pixels, 50000);
  EXPECT_EQ(lit.within, lit.pixels);
}

TEST(Diffuse, ExactRadianceGivesTheExactAlbedo) {
  const test::BrdfScene& s = test::brdf_scene();
  RadianceImage kd;
  Mask valid;
  estimate_diffuse(s.diffuse, s.positions, s.truth.normals, s.lights, {}, kd, valid);
  double worst = 0.0;
  for (int r = 0; r < s.intrinsics.height; r += 2) {
    for (int c = 0; c < s.intrinsics.width; c += 2) {
      if (!valid(r, c) || s.shadowed(r, c)) continue;
      const Float3 e = kd(r, c) - s.truth.albedo(r, c);
      worst = std::max<double>(worst, std::max({std::abs(e.x), std::abs(e.y), std::abs(e.z)}));
    }
  }
  EXPECT_LT(worst, 1e-4);
}

TEST(Diffuse, ShadowsDarkenAndMissingGeometryIsInvalid) {
  const test::BrdfScene& s = test::brdf_scene();
  RadianceImage kd;
  Mask valid;
  estimate_diffuse(s.diffuse, s.positions, s.truth.normals, s.lights, {}, kd, valid);
  int shadowed = 0, darker = 0;
  for (int r = 0; r < s.intrinsics.height; ++r) {
    for (int c = 0; c < s.intrinsics.width; ++c) {
      if (!s.shadowed(r, c) || !valid(r, c)) continue;
      ++shadowed;
      darker += kd(r, c).y < s.truth.albedo(r, c).y;
    }
  }
  EXPECT_GT(shadowed, 100);
  EXPECT_EQ(darker, shadowed);  // shadows are not modelled: k_d comes out too dark there
  PositionMap no_positions(s.intrinsics.width, s.intrinsics.height);
  estimate_diffuse(s.diffuse, no_positions, s.truth.normals, s.lights, {}, kd, valid);
  for (const auto v : valid.pixels()) ASSERT_EQ(v, 0);
}

}  // namespace
}  // namespace relight::brdf
