// Caustic photons (dir/caustic_photons.h) beyond the lights' caustics, which specular_dir_test.cpp
// measures: the discs photons are spread over, and the indirect light through mirrors and glass
// (trace_vpl_caustic_photons) - the photons a VPL sends at the specular objects bring the light
// they pass on to a diffuse surface, which the VPL's imperfect shadow map cannot (it sees them
// as occluders).
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <numbers>

#include "relight/render/dir/caustic_photons.h"
#include "relight/render/dir/gbuffer.h"
#include "relight/render/scene/sampler.h"
#include "relight/render/scene/specular_bsdf.h"
#include "relight/render/scene/tessellation.h"
#include "specular_scenes.h"
#include "test_scenes.h"

namespace relight::render {
namespace {

using Eigen::Vector3f;

/// One diffuse VPL of flux `flux` at `position`, facing up, on the floor's material (index 0).
Vpl upward_vpl(const Vector3f& position, float flux) {
  Vpl vpl;
  vpl.position = position;
  vpl.normal = vpl.geometric_normal = vpl.incident = Vector3f::UnitZ();
  vpl.flux = Vector3f::Constant(flux);
  return vpl;
}

DifferentialImages blank_images(int width, int height) {
  return {RadianceImage(width, height), RadianceImage(width, height), CoverageImage(width, height), 1,
          RadianceImage(width, height), RadianceImage(width, height)};
}

/// A photon on the floor (z = 0, lit from above) in world L_rv or L_r.
CausticPhoton floor_photon(float x, float y, bool real_world) {
  return {{x, y, 0.f}, Vector3f::UnitZ(), Vector3f::UnitZ(), Vector3f::Constant(1e-3f), real_world};
}

// Where photons crowd (a focus of 2 mm) their discs shrink to hold about `neighbours` of them; a
// photon alone keeps the widest disc. A photon traced alike in both worlds gets the same disc in
// both, so that it cancels in L_rv - L_r.
TEST(CausticPhotons, CrowdedPhotonsGetSmallDiscsAndLoneOnesTheWidest) {
  std::vector<CausticPhoton> photons;
  Pcg32 rng(5, 1);
  for (int i = 0; i < 4000; ++i) {
    const float x = 0.002f * (rng.uniform() - 0.5f), y = 0.002f * (rng.uniform() - 0.5f);
    photons.push_back(floor_photon(x, y, false));
    photons.push_back(floor_photon(x, y, true));
  }
  for (int i = 0; i < 5; ++i) photons.push_back(floor_photon(0.2f * static_cast<float>(i + 1), 0.3f, false));
  const CausticPhotons discs(photons, PhotonKernel{0.03f, 0.002f, 32});
  // 32 of 4000 photons over a block of (3 x 3 cm)^2: a disc of sqrt(32 * 81e-4 / (4000 pi)) = 4.5 mm.
  const float crowded = std::sqrt(32.f * 81e-4f / (4000.f * std::numbers::pi_v<float>));
  for (std::size_t i = 0; i < 8000; ++i) EXPECT_NEAR(discs.photons()[i].radius, crowded, 1e-5f) << i;
  for (std::size_t i = 8000; i < photons.size(); ++i) EXPECT_FLOAT_EQ(discs.photons()[i].radius, 0.03f);
  int near_focus = 0, beside = 0;
  discs.for_each_near({0.f, 0.f, 0.f}, [&](const CausticPhoton&) { ++near_focus; });
  discs.for_each_near({0.01f, 0.f, 0.f}, [&](const CausticPhoton&) { ++beside; });
  EXPECT_EQ(near_focus, 8000);
  EXPECT_EQ(beside, 0);  // 1 cm from the focus: outside every disc of it
  // One disc for all: what the widest gives every photon.
  const CausticPhotons fixed(photons, PhotonKernel{0.03f, 0.03f, 32});
  fixed.for_each_near({0.01f, 0.f, 0.f}, [&](const CausticPhoton&) { ++beside; });
  EXPECT_EQ(beside, 8000);
}

// A VPL facing up under a perfect ceiling mirror lights the floor as its mirror image would: a
// downward VPL at 2 H - h, so the floor reflects
//   L = (albedo / pi) flux (k_d / pi) cos_y' cos_x / d'^2,   cos_y' = cos_x = (2 H - h) / d'.
// Its own shadow map sees only the mirror; the photons bring that light into L_rv, and L_r, where
// the virtual mirror does not exist, gets none. Measured (100k photons, 0.1 m disc): 0.997 of the
// closed form below the VPL and 1.003 half a metre aside with the photons' rotated Halton
// directions; with independent random directions 0.981 and 0.924 (1.6M photons were needed for
// 0.993 and 1.023).
TEST(VplCausticPhotons, AVplUnderACeilingMirrorLightsTheFloorAsItsMirrorImage) {
  const float albedo = 0.5f, height = 0.5f, ceiling = 1.f, flux = 1.f;
  MrScene scene = test::floor_scene(Vector3f::Constant(albedo), {0, 0, 2}, 0.f);
  scene.meshes.push_back(
      test::with_layer(tessellate_rectangle({0, 0, ceiling}, {0, 0, -1}, {2.f, 0, 0}, {0, 2.f, 0},
                                            scene.add_material(test::specular_material(conductor(), "mirror"))),
                       "mirror", false));
  const std::vector<Vpl> vpls{upward_vpl({0, 0, height}, flux)};
  const RayTracer tracer(scene);
  CausticOptions options;
  options.vpl_photons = 100000;
  options.vpl_radius = 0.1f;  // the light is smooth; a wider disc averages more photons
  const CausticPhotons photons = trace_vpl_caustic_photons(tracer, vpls, options);
  ASSERT_FALSE(photons.empty());
  EXPECT_TRUE(photons.indirect());
  for (const CausticPhoton& q : photons.photons()) EXPECT_FALSE(q.real_world);  // no mirror without the virtual layer

  const MrCamera camera = test::camera_at({0, -1.4, 0.8}, {0, 0, 0}, 64, 48);
  const GBuffer gbuffer = gbuffer_cpu(tracer, camera);
  DifferentialImages images = blank_images(64, 48);
  add_caustic_light(images, gbuffer, scene, photons, camera.camera_to_world.translation().cast<float>());
  const float image_height = 2.f * ceiling - height;
  const auto expected_at = [&](const Float3& p) {
    const double d2 = p.x * p.x + p.y * p.y + image_height * image_height;
    const double cos2 = image_height * image_height / d2;
    return albedo / std::numbers::pi * flux * albedo / std::numbers::pi * cos2 / d2;
  };
  for (const auto& [lo, hi] : {std::pair{Eigen::Vector2f(-0.15f, -0.15f), Eigen::Vector2f(0.15f, 0.15f)},
                               std::pair{Eigen::Vector2f(0.35f, -0.15f), Eigen::Vector2f(0.65f, 0.15f)}}) {
    const auto pixels = test::floor_pixels(scene, camera, lo, hi);
    ASSERT_GT(pixels.size(), 30u);
    double expected = 0.0;
    for (const auto& [row, col] : pixels) expected += expected_at(gbuffer.position(row, col));
    expected /= static_cast<double>(pixels.size());
    const Eigen::Vector3d rv = test::mean_over(images.real_virtual, pixels);
    const Eigen::Vector3d indirect = test::mean_over(images.indirect_real_virtual, pixels);
    std::cout << "VPL light through the mirror at x " << lo.x() << ".." << hi.x() << ": " << rv.x() / expected
              << " of the closed form\n";
    EXPECT_NEAR(rv.x(), expected, 0.03 * expected);
    EXPECT_NEAR(indirect.x(), rv.x(), 1e-6 * expected);  // the VPLs' light, smoothed with the rest
    EXPECT_LT(test::mean_over(images.real, pixels).x(), 1e-9);
  }
}

// A VPL that exists in L_r only (the real surface behind a virtual object, vpl.h) sends no photon
// into L_rv, and one facing away from the mirror none at all.
TEST(VplCausticPhotons, AVplSendsPhotonsOnlyInItsOwnWorldsAndOnlyForwards) {
  MrScene scene = test::floor_scene(Vector3f::Constant(0.5f), {0, 0, 2}, 0.f);
  scene.meshes.push_back(
      test::with_layer(tessellate_rectangle({0, 0, 1.f}, {0, 0, -1}, {2.f, 0, 0}, {0, 2.f, 0},
                                            scene.add_material(test::specular_material(conductor(), "mirror"))),
                       "mirror", false));
  const RayTracer tracer(scene);
  CausticOptions options;
  options.vpl_photons = 4096;
  Vpl real_only = upward_vpl({0, 0, 0.5f}, 1.f);
  real_only.in_real_virtual = false;
  EXPECT_TRUE(trace_vpl_caustic_photons(tracer, std::vector<Vpl>{real_only}, options).empty());
  Vpl downward = upward_vpl({0, 0, 0.5f}, 1.f);
  downward.normal = downward.geometric_normal = -Vector3f::UnitZ();
  // Its light meets the floor first: direct light, its shadow map's share.
  EXPECT_TRUE(trace_vpl_caustic_photons(tracer, std::vector<Vpl>{downward}, options).empty());
}

}  // namespace
}  // namespace relight::render
