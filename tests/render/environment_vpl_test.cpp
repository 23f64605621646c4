// The environment's directional lights through emitter VPLs (vpl.h "Emitters", Knecht 2010
// §3.6): one emitter per flagged light, no shadow-map views for it, and on the CPU the same
// shading as the shadow-mapped directional light, with the shadow through its ISM.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "relight/core/error.h"
#include "relight/render/dir/dir.h"
#include "relight/render/dir/shadow_maps.h"
#include "relight/render/reference/dir_exact.h"
#include "test_scenes.h"

namespace relight::render {
namespace {

using test::diffuse;

MrLight sun(const Eigen::Vector3f& towards_light, float irradiance, bool through_vpl) {
  MrLight light;
  light.kind = LightKind::Directional;
  light.direction = towards_light.normalized();
  light.intensity = Eigen::Vector3f::Constant(irradiance);
  light.through_vpl = through_vpl;
  return light;
}

/// The floor and red virtual cube of the DIR tests, lit by one sun (through its emitter VPL or
/// by its shadow maps) instead of the point light.
MrScene sunlit_cube(bool through_vpl) {
  MrScene scene = test::floor_scene(Eigen::Vector3f::Constant(0.8f), {0.f, 0.f, 2.f}, 1.f);
  test::add_virtual_box(scene, synth::Box{{-0.2, -0.2, 0.0}, {0.2, 0.2, 0.4}}, diffuse({0.9f, 0.1f, 0.1f}, "red cube"));
  scene.lights = {sun({1.f, 0.1f, 1.2f}, 2.f, through_vpl)};
  return scene;
}

std::vector<Vpl> vpls_of(const MrScene& scene, int count) {
  VplOptions options;
  options.count = count;
  return generate_vpls(scene, RayTracer(scene), options);
}

TEST(EnvironmentVpls, EachFlaggedLightGetsOneEmitterAfterTheBounceVpls) {
  MrScene scene = sunlit_cube(false);
  scene.lights.push_back(sun({-0.3f, 0.5f, 1.f}, 0.5f, false));
  const std::vector<Vpl> plain = vpls_of(scene, 64);
  scene.lights[0].through_vpl = true;
  const std::vector<Vpl> flagged = vpls_of(scene, 64);
  ASSERT_EQ(flagged.size(), plain.size() + 1) << "one emitter, the bounce VPLs unchanged";
  for (std::size_t i = 0; i < plain.size(); ++i) {
    EXPECT_FALSE(plain[i].emitter());
    EXPECT_EQ(flagged[i].position, plain[i].position);
    EXPECT_EQ(flagged[i].flux, plain[i].flux);
  }
  const Vpl& emitter = flagged.back();
  EXPECT_TRUE(emitter.emitter());
  EXPECT_EQ(emitter.light, 0u);
  EXPECT_EQ(emitter.flux, scene.lights[0].intensity) << "its irradiance";
  EXPECT_TRUE(emitter.incident.isApprox(scene.lights[0].direction, 1e-6f));
  EXPECT_TRUE(emitter.normal.isApprox(-scene.lights[0].direction, 1e-6f));
  EXPECT_GT(emitter.position.dot(scene.lights[0].direction), 50.f) << "far out along the light";
  EXPECT_EQ(emitter.in_real, scene.lights[0].real);
  // The flux tally of the VPL budget counts first bounces only: the emitter's W/m^2 stay out.
  EXPECT_EQ(vpl_flux_per_light(flagged, 2), vpl_flux_per_light(plain, 2));
}

TEST(EnvironmentVpls, FlaggedLightsGetNoShadowMapViews) {
  MrScene scene = sunlit_cube(false);
  scene.lights.push_back(sun({-0.3f, 0.5f, 1.f}, 0.5f, true));
  const ShadowLayout layout = plan_shadow_views(scene, 128);
  EXPECT_GT(layout.light_views[0][1], 0u) << "the shadow-mapped sun has views";
  EXPECT_EQ(layout.light_views[1][1], 0u);
  scene.lights.pop_back();
  EXPECT_EQ(plan_shadow_views(scene, 128).views.size(), layout.views.size());
}

TEST(EnvironmentVpls, OnlyADirectionalLightCanComeThroughAVpl) {
  MrScene scene = sunlit_cube(true);
  EXPECT_NO_THROW(scene.validate());
  scene.lights.front().kind = LightKind::Point;
  EXPECT_THROW(scene.validate(), Error);
}

/// Floor pixels of `pixels` where the virtual cube takes more than half of the light.
int shadowed(const DifferentialImages& images, const std::vector<std::pair<int, int>>& pixels) {
  return static_cast<int>(std::count_if(pixels.begin(), pixels.end(), [&](const auto& p) {
    const Float3 rv = images.real_virtual(p.first, p.second), r = images.real(p.first, p.second);
    return rv.x + rv.y + rv.z < 0.5f * (r.x + r.y + r.z);
  }));
}

// The sun through its emitter VPL against the same sun shadow-mapped, both on the CPU twin of
// the Vulkan renderer (same bounce VPLs), and against exact visibility (dir_exact, same VPLs):
// the emitter's ISM shadow of the cube on the floor, with the default ISMs (64-texel tiles, 1024
// points; one pull-push level for emitters, ism.h). Measured (96 x 72, 128 VPLs): shadowed floor
// pixels emitter 130, shadow maps 131, exact 131 (166 with the bounce VPLs' 3 pull-push levels,
// whose coarse fill grows the silhouette); umbra delta error 0.000 against exact visibility; the
// lit floor as the shadow-mapped sun's, no pixel wrongly self-shadowed (3 of 190 with 3 levels).
TEST(EnvironmentVpls, EmitterShadowsTheFloorLikeTheShadowMappedSun) {
  const MrScene mapped_scene = sunlit_cube(false), vpl_scene = sunlit_cube(true);
  const MrCamera camera = test::camera_at({-1.2, -1.4, 1.4}, {-0.3, 0, 0}, 96, 72);
  DirRenderOptions options;
  options.shadow_tile = 512;
  options.shading.min_distance = 0.05f;
  const DifferentialImages mapped = render_dir_cpu(mapped_scene, camera, vpls_of(mapped_scene, 128), options);
  const std::vector<Vpl> vpls = vpls_of(vpl_scene, 128);
  const DifferentialImages through_vpl = render_dir_cpu(vpl_scene, camera, vpls, options);
  const DifferentialImages exact =
      shade_instant_radiosity(vpl_scene, RayTracer(vpl_scene), camera, vpls, options.shading);

  // The sun comes from +x, 50 degrees up: the 40 cm cube's umbra reaches x = -0.53 m.
  const Eigen::Vector2f umbra_lo{-0.45f, -0.12f}, umbra_hi{-0.25f, 0.1f};
  const auto around = test::floor_pixels(vpl_scene, camera, {-1.f, -0.6f}, {-0.1f, 0.6f});
  const auto lit = test::floor_pixels(vpl_scene, camera, {-1.2f, 0.5f}, {-0.6f, 1.0f});
  ASSERT_GT(lit.size(), 20u);
  const double vpl_lit = test::mean_over(through_vpl.real, lit).sum(),
               mapped_lit = test::mean_over(mapped.real, lit).sum();
  const double error = test::delta_error_on_floor(vpl_scene, camera, exact, through_vpl, umbra_lo, umbra_hi);
  const int vpl_shadow = shadowed(through_vpl, around), mapped_shadow = shadowed(mapped, around),
            exact_shadow = shadowed(exact, around);
  // Lit floor pixels the emitter's real tile wrongly shadows: holes between the floor's splats
  // filled from a coarse pull-push level, whose averaged depth on the slanted floor can come out
  // nearer than the bias allows.
  const auto self_shadowed = std::count_if(lit.begin(), lit.end(), [&](const auto& p) {
    return through_vpl.real(p.first, p.second).x < 0.5f * mapped.real(p.first, p.second).x;
  });
  std::printf(
      "shadowed floor pixels: emitter %d, shadow maps %d, exact %d; umbra delta error %.3f; lit floor %.5f vs "
      "%.5f, %d of %zu pixels self-shadowed\n",
      vpl_shadow, mapped_shadow, exact_shadow, error, vpl_lit, mapped_lit, static_cast<int>(self_shadowed), lit.size());
  ASSERT_GT(exact_shadow, 80);
  EXPECT_GT(vpl_shadow, exact_shadow * 95 / 100) << "the cube shadows the sun's emitter";
  EXPECT_LT(vpl_shadow, exact_shadow * 110 / 100) << "the silhouette barely grows";
  EXPECT_LT(error, 0.12);
  EXPECT_NEAR(vpl_lit, mapped_lit, 0.005 * mapped_lit) << "the same direct light where nothing occludes it";
  EXPECT_LE(static_cast<std::size_t>(self_shadowed), lit.size() / 50);
}

}  // namespace
}  // namespace relight::render
