// First-bounce VPLs of spot lights from reflective shadow maps (reflective_shadow_map.h, VPL
// source ReflectiveShadowMaps in vpl.h) against the ray-traced generator: the same flux reaches
// each world's surfaces, split the same way between real, virtual and real-only VPLs.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "support/vulkan_test_env.h"
#include "relight/core/error.h"
#include "relight/render/vpl/reflective_shadow_map.h"
#include "relight/render/vpl/reflective_shadow_map_vk.h"
#include "relight/render/vpl/vpl.h"
#include "test_scenes.h"

namespace relight::render {
namespace {

using test::diffuse;

/// A grey floor lit from 2 m above by a spot light (outer 40 degrees, inner 30, all on the floor)
/// and a red virtual box under it.
MrScene spot_scene(bool real_light) {
  MrScene scene = test::floor_scene(Eigen::Vector3f::Constant(0.6f), {0.f, 0.f, 2.f}, 5.f);
  scene.lights[0] = spot_light({0.f, 0.f, 2.f}, {0.1f, 0.f, -1.f}, 40.f, 30.f, {5.f, 4.f, 3.f}, real_light);
  test::add_virtual_box(scene, synth::Box{{-0.1, -0.3, 0.0}, {0.4, 0.2, 0.5}}, diffuse({0.9f, 0.1f, 0.1f}, "red box"));
  return scene;
}

/// Luminance of the first-bounce flux per kind of VPL: [real+virtual world on real surfaces,
/// real+virtual world on virtual surfaces, real-only world].
std::array<double, 3> flux_by_kind(const std::vector<Vpl>& vpls) {
  std::array<double, 3> sum{};
  for (const Vpl& vpl : vpls) {
    const double y = 0.2126 * vpl.flux.x() + 0.7152 * vpl.flux.y() + 0.0722 * vpl.flux.z();
    if (vpl.in_real_virtual) sum[vpl.on_real_surface ? 0 : 1] += y;
    if (vpl.in_real) sum[2] += y;
  }
  return sum;
}

std::vector<Vpl> traced(const MrScene& scene, const RayTracer& tracer) {
  // Many stratified samples, half aimed at the box, so that the reference's noise (<1 % on
  // each sum) is well below the tolerance.
  VplOptions options;
  options.count = 32768;
  options.virtual_share = 0.5f;
  return generate_vpls(scene, tracer, options);
}

std::vector<Vpl> from_rsms(const MrScene& scene, const RayTracer& tracer, int count,
                           ReflectiveShadowMapsVk* gpu = nullptr) {
  VplOptions options;
  options.count = count;
  options.source = VplSource::ReflectiveShadowMaps;
  return generate_vpls(scene, tracer, options, {.reflective_shadow_maps = gpu});
}

TEST(RsmVpls, RealSpotLightMatchesTheRayTracedFlux) {
  const MrScene scene = spot_scene(true);
  const RayTracer tracer(scene);
  const std::vector<Vpl> rsm = from_rsms(scene, tracer, 1024);
  EXPECT_EQ(rsm.size(), 1024u);  // one VPL per slot: the two RSMs never both hold a texel's VPL
  const auto expected = flux_by_kind(traced(scene, tracer));
  const auto got = flux_by_kind(rsm);
  for (int kind = 0; kind < 3; ++kind) {
    ASSERT_GT(expected[static_cast<std::size_t>(kind)], 0.0) << "kind " << kind;
    EXPECT_NEAR(got[static_cast<std::size_t>(kind)] / expected[static_cast<std::size_t>(kind)], 1.0, 0.03) << "kind " << kind;
  }
  // The real-only world sees the light's whole cone on the floor, as both generators agree.
  EXPECT_NEAR(got[2] / (got[0] + got[1]), 1.0, 0.01);
  // The slots follow the covered texels: the box's share of VPLs is its share of the coverage.
  const auto maps = reflective_shadow_maps_cpu(scene, tracer, 0, 256);
  ASSERT_EQ(maps.size(), 2u);
  double on_box = 0;
  for (const Vpl& vpl : rsm) on_box += vpl.on_real_surface ? 0.0 : 1.0;
  const double share = static_cast<double>(maps[1].covered()) / static_cast<double>(maps[0].covered() + maps[1].covered());
  EXPECT_NEAR(on_box / 1024.0, share, 1.0 / 1024.0);
  EXPECT_GT(share, 0.03);
}

TEST(RsmVpls, VirtualSpotLightMatchesTheRayTracedFlux) {
  const MrScene scene = spot_scene(false);
  const RayTracer tracer(scene);
  // One RSM for floor and box: the box (5 % of the texels, darker) gets ~2 % of the samples, so
  // enough slots that it holds ~360 and the rounding of its count stays below 0.3 %.
  const std::vector<Vpl> rsm = from_rsms(scene, tracer, 16384);
  EXPECT_EQ(rsm.size(), 16384u);
  for (const Vpl& vpl : rsm) ASSERT_FALSE(vpl.in_real);
  const auto expected = flux_by_kind(traced(scene, tracer));
  const auto got = flux_by_kind(rsm);
  EXPECT_EQ(got[2], 0.0);
  for (int kind = 0; kind < 2; ++kind)
    EXPECT_NEAR(got[static_cast<std::size_t>(kind)] / expected[static_cast<std::size_t>(kind)], 1.0, 0.03) << "kind " << kind;
}

TEST(RsmVpls, TotalFluxIsTheLightsPowerInItsCone) {
  // The whole cone lands on the floor or the box: the VPLs of the real+virtual world carry the
  // emitted power, the integral of I falloff over the cone (here by a fine 1-D quadrature).
  const MrScene scene = spot_scene(true);
  const RayTracer tracer(scene);
  const MrLight& light = scene.lights[0];
  double power = 0;
  constexpr int kSteps = 20000;
  for (int i = 0; i < kSteps; ++i) {
    const double c = light.cos_outer + (1.0 - light.cos_outer) * (i + 0.5) / kSteps;
    const double x = std::clamp((c - light.cos_outer) / (light.cos_inner - light.cos_outer), 0.0, 1.0);
    power += 2.0 * std::numbers::pi * x * x * (3.0 - 2.0 * x) * (1.0 - light.cos_outer) / kSteps;
  }
  const double luminance = 0.2126 * 5.0 + 0.7152 * 4.0 + 0.0722 * 3.0;
  const auto got = flux_by_kind(from_rsms(scene, tracer, 256));
  EXPECT_NEAR((got[0] + got[1]) / (power * luminance), 1.0, 0.01);
}

TEST(RsmVpls, RayTracedStaysTheDefaultAndBadSizesAreRejected) {
  EXPECT_EQ(VplOptions{}.source, VplSource::RayTraced);
  const MrScene scene = spot_scene(true);
  const RayTracer tracer(scene);
  VplOptions options;
  options.source = VplSource::ReflectiveShadowMaps;
  options.rsm_size = 100;
  EXPECT_THROW((void)generate_vpls(scene, tracer, options), Error);
}

// ---- Rasterised RSMs (reflective_shadow_map_vk.h) --------------------------------------------

class RsmVkTest : public relight::test::VulkanTest {};

/// How a rasterised RSM differs from the ray-cast one, texel by texel.
struct RsmComparison {
  int covered_cpu = 0, coverage_mismatch = 0, both = 0, same_surface = 0, flux_differs = 0, occlusion_differs = 0;
};

RsmComparison compare(const ReflectiveShadowMap& gpu, const ReflectiveShadowMap& cpu) {
  RsmComparison c;
  for (std::size_t i = 0; i < cpu.texels.size(); ++i) {
    const RsmTexel &g = gpu.texels[i], &r = cpu.texels[i];
    c.covered_cpu += r.hit ? 1 : 0;
    c.occlusion_differs += g.occluded_by_virtual != r.occluded_by_virtual ? 1 : 0;
    if (g.hit.has_value() != r.hit.has_value()) {
      ++c.coverage_mismatch;
      continue;
    }
    if (!r.hit) continue;
    ++c.both;
    c.flux_differs += (g.flux - r.flux).norm() > 1e-6f * r.flux.norm() || g.direction != r.direction ? 1 : 0;
    // The same surface: material and world, within 5 mm, and the same plane (the rasterised
    // normal faces the light; the ray cast one is the triangle's).
    c.same_surface += g.hit->material == r.hit->material && g.hit->real == r.hit->real &&
                              (g.hit->point - r.hit->point).norm() < 0.005f &&
                              std::abs(g.hit->shading_normal.dot(r.hit->shading_normal)) > 0.999f
                          ? 1
                          : 0;
  }
  return c;
}

/// The synthetic room (tessellated, smooth-shaded objects) with the glossy pebble on its table,
/// lit by a real spot light above the table.
MrScene room_scene() {
  MrScene scene = test::indoor_with_pebble();
  scene.lights = {spot_light({0.3f, -0.25f, 1.6f}, {0.05f, 0.05f, -1.f}, 15.f, 10.f, {4.f, 4.f, 4.f}, true)};
  return scene;
}

// Measured (128² texels): the floor-and-box scene agrees in every texel (real light: 16128 and
// 625 covered texels; virtual light: 16128); in the room with the pebble (real light, 15 degrees)
// as well: 16384 and 1445 texels. A principal point shifted by 0.2 texel makes 15-128 texels
// differ per map.
TEST_F(RsmVkTest, RasterisedMapsEqualTheRayCastOnes) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  ReflectiveShadowMapsVk rasteriser(context);
  for (const int which : {0, 1, 2}) {
    const bool real_light = which != 1;
    const MrScene scene = which == 2 ? room_scene() : spot_scene(real_light);
    const RayTracer tracer(scene);
    rasteriser.set_scene(scene);
    const auto gpu = rasteriser.render(scene, 0, 128);
    const auto cpu = reflective_shadow_maps_cpu(scene, tracer, 0, 128);
    ASSERT_EQ(gpu.size(), cpu.size());
    for (std::size_t m = 0; m < cpu.size(); ++m) {
      const RsmComparison c = compare(gpu[m], cpu[m]);
      std::printf("%s, map %zu: %d covered texels; coverage differs in %d, surface in %d of %d, flux in %d, "
                  "occlusion in %d\n",
                  which == 2 ? "room" : real_light ? "real light" : "virtual light", m, c.covered_cpu, c.coverage_mismatch, c.both - c.same_surface, c.both,
                  c.flux_differs, c.occlusion_differs);
      ASSERT_GT(c.covered_cpu, 500);
      EXPECT_LE(c.coverage_mismatch, c.covered_cpu / 100) << "map " << m;  // triangle edges only
      EXPECT_GE(c.same_surface, c.both * 99 / 100) << "map " << m;
      EXPECT_EQ(c.flux_differs, 0) << "map " << m;
      EXPECT_LE(c.occlusion_differs, c.covered_cpu / 100) << "map " << m;
      EXPECT_NEAR(static_cast<double>(gpu[m].covered()), static_cast<double>(cpu[m].covered()), 0.01 * cpu[m].covered());
    }
  }
  EXPECT_GT(rasteriser.last_gpu_ms(), 0.0);
}

TEST_F(RsmVkTest, VplsFromRasterisedMapsCarryTheRayCastFlux) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  ReflectiveShadowMapsVk rasteriser(context);
  const MrScene scene = spot_scene(true);
  const RayTracer tracer(scene);
  rasteriser.set_scene(scene);
  const auto gpu = flux_by_kind(from_rsms(scene, tracer, 1024, &rasteriser));
  const auto cpu = flux_by_kind(from_rsms(scene, tracer, 1024));
  for (std::size_t kind = 0; kind < 3; ++kind) {
    ASSERT_GT(cpu[kind], 0.0) << "kind " << kind;
    EXPECT_NEAR(gpu[kind] / cpu[kind], 1.0, 0.01) << "kind " << kind;
  }
}

}  // namespace
}  // namespace relight::render
