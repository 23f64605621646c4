// Differential instant radiosity on Vulkan: every GPU step against its CPU reference (shadow
// maps by ray casting, ISMs by the same splats, shading by shade_dir_from_maps), then the whole
// method against the exact-visibility CPU DIR and the path tracer.
#include "relight/render/dir/dir_vk.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "support/vulkan_test_env.h"
#include "relight/core/error.h"
#include "relight/synth/scene.h"
#include "relight/vk/context.h"
#include "test_scenes.h"

namespace relight::render {
namespace {

using test::camera_at;
using test::diffuse;

class DirVkTest : public relight::test::VulkanTest {};

/// A white floor and a back wall, a real point light, and a red virtual cube on the floor.
MrScene cube_scene() {
  MrScene scene = test::floor_scene(Eigen::Vector3f::Constant(0.8f), {1.0f, 0.f, 1.5f}, 4.f);
  TriangleMesh wall = truth::tessellate(synth::Rect{{0, 2, 1}, {0, -1, 0}, {1, 0, 0}, {0, 0, 1}, 2, 1},
                                 scene.add_material(diffuse({0.3f, 0.6f, 0.3f}, "green wall")));
  scene.meshes.push_back(wall);
  test::add_virtual_box(scene, synth::Box{{-0.2, -0.2, 0.0}, {0.2, 0.2, 0.4}}, diffuse({0.9f, 0.1f, 0.1f}, "red cube"));
  return scene;
}

DirRenderOptions test_options() {
  DirRenderOptions options;
  options.shadow_tile = 256;
  options.ism.tile = 32;
  options.ism.points_per_vpl = 512;
  options.ism.pull_push_levels = 2;
  options.shading.min_distance = 0.05f;
  options.backend = DirBackend::Gpu;  // these tests hold the Vulkan steps to their references
  return options;
}

std::vector<Vpl> make_vpls(const MrScene& scene, int count) {
  VplOptions options;
  options.count = count;
  return generate_vpls(scene, RayTracer(scene), options);
}

// Interleaved sampling (n = 4) and the merge against every pixel seeing every VPL (n = 1), on
// the CPU mirror: the merged indirect light's mean relative error where the 4 x 4 window crosses
// an edge (a neighbour on another surface), and elsewhere. Measured (160x120, 64 light
// samples): interior 0.030, edges 0.190; 0.352 at edges when a subset missing from the window
// was simply left out.
TEST(DirMerge, InterleavedIndirectLightStaysCloseToTheFullSumAtEdges) {
  const MrScene scene = test::indoor_with_pebble();
  const MrCamera camera = camera_at({1.3, -1.1, 1.4}, {0.2, -0.1, 0.75}, 160, 120);
  const std::vector<Vpl> vpls = make_vpls(scene, 64);
  DirRenderOptions options = test_options();
  options.backend = DirBackend::Cpu;
  GBuffer gbuffer;
  options.interleave = 1;
  const DifferentialImages full = render_dir_cpu(scene, camera, vpls, options, &gbuffer);
  options.interleave = 4;
  const DifferentialImages merged = render_dir_cpu(scene, camera, vpls, options);
  const auto luminance = [](const Float3& c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; };
  double error[2] = {0, 0};
  int count[2] = {0, 0};
  for (int y = 2; y < 118; ++y)
    for (int x = 2; x < 158; ++x) {
      const double reference = luminance(full.indirect_real_virtual(y, x));
      if (gbuffer.distance(y, x) == 0.f || reference < 1e-3) continue;
      bool edge = false;
      for (int dy = -2; dy < 2; ++dy)
        for (int dx = -2; dx < 2; ++dx) {
          const float dq = gbuffer.distance(y + dy, x + dx);
          edge = edge || dq == 0.f || std::abs(dq - gbuffer.distance(y, x)) > 0.05f * gbuffer.distance(y, x) ||
                 dot(gbuffer.normal(y + dy, x + dx), gbuffer.normal(y, x)) < 0.9f ||
                 gbuffer.virtual_surface(y + dy, x + dx) != gbuffer.virtual_surface(y, x);
        }
      error[edge ? 1 : 0] += std::abs(luminance(merged.indirect_real_virtual(y, x)) - reference) / reference;
      ++count[edge ? 1 : 0];
    }
  ASSERT_GT(count[1], 500);
  const double interior = error[0] / count[0], at_edges = error[1] / count[1];
  std::printf("merged indirect light against the full sum: interior %.3f (%d px), edges %.3f (%d px)\n", interior,
              count[0], at_edges, count[1]);
  EXPECT_LT(at_edges, 0.25);
  EXPECT_LT(interior, 0.05);
}

TEST_F(DirVkTest, ShadowAtlasMatchesTheRayCastReference) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  MrScene scene = test::indoor_with_pebble();
  MrLight spot;
  spot.kind = LightKind::Spot;
  spot.position = {0.8f, -0.9f, 2.0f};
  spot.direction = Eigen::Vector3f(-0.3f, 0.5f, -1.f).normalized();
  spot.real = false;
  scene.lights.push_back(spot);
  MrLight sun;
  sun.kind = LightKind::Directional;
  sun.direction = Eigen::Vector3f(0.3f, -0.4f, 1.f).normalized();
  scene.lights.push_back(sun);
  DirRenderOptions options = test_options();
  options.shadow_tile = 128;
  DirRendererVk renderer(context, 32, 24);
  renderer.set_scene(scene, options);
  (void)renderer.render(camera_at({1.3, -1.1, 1.4}, {0.2, -0.1, 0.75}, 32, 24), {}, options);
  const ShadowLayout& layout = renderer.shadow_layout();
  ASSERT_EQ(layout.light_views.size(), scene.lights.size());
  EXPECT_EQ(layout.light_views.back()[1], 1u) << "directional: one orthographic view";
  EXPECT_EQ(layout.light_views[layout.light_views.size() - 2][1], 1u) << "narrow spot: one perspective view";
  const std::vector<float> gpu = renderer.last_shadow_atlas();
  const std::vector<float> cpu = shadow_atlas_cpu(RayTracer(scene), layout);
  ASSERT_EQ(gpu.size(), cpu.size());
  std::size_t both = 0, agree = 0, coverage_mismatch = 0, virtual_texels = 0;
  const int virtual_top = layout.atlas_height() / 2;
  for (std::size_t i = 0; i < cpu.size(); ++i) {
    const bool seen_gpu = gpu[i] < kShadowEmpty, seen_cpu = cpu[i] < kShadowEmpty;
    if (seen_gpu != seen_cpu) {
      ++coverage_mismatch;
      continue;
    }
    if (!seen_cpu) continue;
    ++both;
    if (static_cast<int>(i / static_cast<std::size_t>(layout.atlas_width())) >= virtual_top) ++virtual_texels;
    if (std::abs(gpu[i] - cpu[i]) <= 0.01f * std::abs(cpu[i]) + 0.005f) ++agree;
  }
  EXPECT_GT(both, cpu.size() / 4) << "the real layer (half the atlas) is mostly covered";
  EXPECT_GT(virtual_texels, 50u) << "the pebble is in the lights' views";
  EXPECT_GT(agree, both * 98 / 100);
  EXPECT_LT(coverage_mismatch, cpu.size() / 100);
}

// MrScene::coarse_real_meshes replace the real meshes in the real layer of the shadow maps: here
// a roof over the room, which only the real layer's views see.
TEST_F(DirVkTest, CoarseRealMeshesCastTheRealLayersShadows) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  MrScene scene = test::indoor_with_pebble();
  MrLight sun;
  sun.kind = LightKind::Directional;
  sun.direction = Eigen::Vector3f(0.2f, -0.1f, 1.f).normalized();
  scene.lights = {sun};
  TriangleMesh roof;
  roof.name = "roof";
  roof.positions = {{-10.f, -10.f, 2.5f}, {10.f, -10.f, 2.5f}, {10.f, 10.f, 2.5f}, {-10.f, 10.f, 2.5f}};
  roof.triangles = {{0, 1, 2}, {0, 2, 3}};
  roof.triangle_material = {0, 0};
  scene.coarse_real_meshes = {roof};
  DirRenderOptions options = test_options();
  options.shadow_tile = 64;
  DirRendererVk renderer(context, 32, 24);
  renderer.set_scene(scene, options);
  (void)renderer.render(camera_at({1.3, -1.1, 1.4}, {0.2, -0.1, 0.75}, 32, 24), {}, options);
  const ShadowLayout& layout = renderer.shadow_layout();
  const std::vector<float> gpu = renderer.last_shadow_atlas();
  const std::vector<float> cpu = shadow_atlas_cpu(RayTracer(coarse_scene(scene)), layout);
  const std::vector<float> without =
      shadow_atlas_cpu(RayTracer(MrScene{scene.materials, scene.meshes, scene.lights, {}, {}}), layout);
  ASSERT_EQ(gpu.size(), cpu.size());
  const std::size_t half = cpu.size() / 2;  // the real layer's rows, then the virtual layer's
  std::size_t real_agree = 0, real_differs_from_meshes = 0, virtual_agree = 0;
  for (std::size_t i = 0; i < cpu.size(); ++i) {
    const bool agree = (gpu[i] >= kShadowEmpty && cpu[i] >= kShadowEmpty) ||
                       std::abs(gpu[i] - cpu[i]) <= 0.01f * std::abs(cpu[i]) + 0.005f;
    if (i < half) {
      real_agree += agree ? 1 : 0;
      real_differs_from_meshes += std::abs(gpu[i] - without[i]) > 0.1f ? 1 : 0;
    } else {
      virtual_agree += agree && cpu[i] == without[i] ? 1 : 0;
    }
  }
  EXPECT_GT(real_agree, half * 99 / 100) << "the rasterised real layer is the roof's";
  EXPECT_GT(real_differs_from_meshes, half * 9 / 10) << "...not the room's";
  EXPECT_GT(virtual_agree, half * 99 / 100) << "the virtual layer is the pebble's, as without stand-ins";
  MrScene virtual_copy = scene;
  virtual_copy.coarse_real_meshes.front().real = false;
  EXPECT_THROW(virtual_copy.validate(), Error);
}

/// The cube scene with a sun that reaches it through its emitter VPL (vpl.h).
MrScene cube_scene_with_emitter() {
  MrScene scene = cube_scene();
  MrLight sun;
  sun.kind = LightKind::Directional;
  sun.direction = Eigen::Vector3f(-0.6f, -0.3f, 1.f).normalized();
  sun.intensity = Eigen::Vector3f::Constant(1.5f);
  sun.through_vpl = true;
  scene.lights.push_back(sun);
  return scene;
}

void expect_ism_atlas_matches_cpu(vk::VulkanContext& context, const MrScene& scene) {
  const DirRenderOptions options = test_options();
  const std::vector<Vpl> vpls = make_vpls(scene, 48);
  DirRendererVk renderer(context, 32, 24);
  renderer.set_scene(scene, options);
  (void)renderer.render(camera_at({0.2, -1.5, 1.4}, {0, 0, 0.1}, 32, 24), vpls, options);
  const std::vector<float> gpu = renderer.last_ism_atlas();
  const std::vector<float> cpu = ism_atlas_cpu(renderer.ism_points(), vpls, options.ism);
  ASSERT_EQ(gpu.size(), cpu.size());
  std::size_t seen = 0, agree = 0, virtual_seen = 0;
  const std::size_t half = cpu.size() / 2;
  for (std::size_t i = 0; i < cpu.size(); ++i) {
    if (cpu[i] < kShadowEmpty) {
      ++seen;
      if (i >= half) ++virtual_seen;
    }
    const bool same_state = (gpu[i] < kShadowEmpty) == (cpu[i] < kShadowEmpty);
    if (same_state && (cpu[i] >= kShadowEmpty || std::abs(gpu[i] - cpu[i]) <= 1e-4f * cpu[i])) ++agree;
  }
  EXPECT_GT(seen, half / 2) << "the real layer covers most of every VPL's hemisphere";
  EXPECT_GT(virtual_seen, 100u) << "the cube is seen by the VPLs";
  EXPECT_GT(agree, cpu.size() * 995 / 1000);
}

TEST_F(DirVkTest, IsmAtlasMatchesTheCpuSplatsAndPullPush) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  expect_ism_atlas_matches_cpu(context, cube_scene());
}

void expect_shading_matches_cpu(vk::VulkanContext& context, const MrScene& scene) {
  const DirRenderOptions options = test_options();
  const std::vector<Vpl> vpls = make_vpls(scene, 64);
  const MrCamera camera = camera_at({0.2, -1.5, 1.4}, {0, 0, 0.1}, 64, 48);
  DirRendererVk renderer(context, 64, 48);
  renderer.set_scene(scene, options);
  const DifferentialImages gpu = renderer.render(camera, vpls, options);
  const DifferentialImages cpu = shade_dir_from_maps(
      renderer.last_gbuffer(), scene, camera.camera_to_world.translation().cast<float>(), renderer.shadow_layout(),
      renderer.last_shadow_atlas(), vpls, renderer.last_ism_atlas(), renderer.ism_points(), options);
  int close = 0, virtual_pixels = 0;
  const int pixels = 64 * 48;
  for (int i = 0; i < pixels; ++i) {
    const float tolerance_rv = 1e-3f * luminance(cpu.real_virtual.pixels()[i]) + 1e-5f;
    const float tolerance_r = 1e-3f * luminance(cpu.real.pixels()[i]) + 1e-5f;
    const bool rv = length(gpu.real_virtual.pixels()[i] - cpu.real_virtual.pixels()[i]) <= tolerance_rv;
    const bool r = length(gpu.real.pixels()[i] - cpu.real.pixels()[i]) <= tolerance_r;
    if (rv && r) ++close;
    EXPECT_EQ(gpu.virtual_coverage.pixels()[i], cpu.virtual_coverage.pixels()[i]);
    virtual_pixels += gpu.virtual_coverage.pixels()[i] > 0.5f;
  }
  EXPECT_GT(virtual_pixels, 50);
  // A handful of pixels may sit exactly on a visibility edge where the GPU's fused arithmetic
  // rounds the other way.
  EXPECT_GT(close, pixels * 99 / 100);
}

TEST_F(DirVkTest, ShadingMatchesTheCpuMirrorOnTheSameMaps) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  expect_shading_matches_cpu(context, cube_scene());
}

// A textured virtual cube: the G-buffer's texture coordinates and footprint, the packed textures
// and the VPLs' texture factors, and the merge's re-texturing of the indirect light, on the GPU
// as in the CPU mirror.
TEST_F(DirVkTest, TexturedShadingMatchesTheCpuMirror) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  MrScene scene = cube_scene();
  test::texture_virtual_meshes(scene);
  // With a KHR_texture_transform (rotated, stretched, shifted): the GPU applies it as the CPU.
  const auto transformed = std::make_shared<const Texture>(
      "checker", test::checkerboard(32, 8, Rgb8{230, 40, 30}, Rgb8{240, 240, 240}), TextureWrap::Repeat,
      TextureWrap::Repeat, TextureEncoding::Srgb, UvTransform::gltf({0.3f, -0.2f}, 0.5f, {0.9f, 0.7f}));
  for (PhongMaterial& m : scene.materials)
    if (m.base_color) {
      m.base_color = transformed;
      m.kd = Eigen::Vector3f::Constant(0.8f);         // the colours come from the texture alone
      m.emission = Eigen::Vector3f::Constant(0.02f);  // and a faint glow through the same texture
      m.emission_texture = m.base_color;
    }
  expect_shading_matches_cpu(context, scene);
  DirRendererVk renderer(context, 64, 48);
  renderer.set_scene(scene, test_options());
  const DifferentialImages images =
      renderer.render(camera_at({0.2, -1.5, 1.4}, {0, 0, 0.1}, 64, 48), make_vpls(scene, 64), test_options());
  const GBuffer& gbuffer = renderer.last_gbuffer();
  int red = 0, white = 0;
  for (std::size_t i = 0; i < images.real_virtual.size(); ++i) {
    if (!gbuffer.virtual_surface.pixels()[i]) continue;
    EXPECT_GT(gbuffer.texcoord.pixels()[i].z, 0.f) << "the cube has texture coordinates";
    const Float3& c = images.real_virtual.pixels()[i];
    if (c.x > 0.f && c.y < 0.3f * c.x) ++red;
    if (c.x > 0.f && c.y > 0.6f * c.x) ++white;
  }
  EXPECT_GT(red, 20) << "the checkerboard's red cells";
  EXPECT_GT(white, 20) << "and its white ones";
}

// A metallic-roughness texture (a checkerboard of rough dielectric and smoother metal) on the
// textured cube, on a material mapped from glTF's factors: the GPU's per-pixel Phong parameters
// and its VPLs' match the CPU mirror.
TEST_F(DirVkTest, MetallicRoughnessShadingMatchesTheCpuMirror) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  MrScene scene = cube_scene();
  test::texture_virtual_meshes(scene);
  const auto mr = std::make_shared<const Texture>("mr", test::checkerboard(16, 2, Rgb8{0, 240, 0}, Rgb8{0, 120, 255}),
                                                  TextureWrap::Repeat, TextureWrap::Repeat, TextureEncoding::Linear);
  for (PhongMaterial& m : scene.materials)
    if (m.base_color) {
      m.metallic_roughness = {{0.9f, 0.6f, 0.3f}, 0.8f, 0.9f};
      static_cast<Phong&>(m) = phong_from_metallic_roughness(m.metallic_roughness);
      m.metallic_roughness_texture = mr;
    }
  expect_shading_matches_cpu(context, scene);
}

// A normal map (cells tilted 30 degrees towards T and towards B) on the textured cube: the GPU
// G-buffer's tangent frames from screen derivatives and the shading's bent normals match the CPU
// mirror reading the same G-buffer; and the bend shows (the cube shades unlike its flat self).
TEST_F(DirVkTest, NormalMappedShadingMatchesTheCpuMirror) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  MrScene scene = cube_scene();
  test::texture_virtual_meshes(scene);
  const MrScene flat = scene;
  const auto normals =
      std::make_shared<const Texture>("normals", test::checkerboard(16, 4, Rgb8{192, 128, 239}, Rgb8{128, 64, 239}),
                                      TextureWrap::Repeat, TextureWrap::Repeat, TextureEncoding::Linear);
  for (PhongMaterial& m : scene.materials)
    if (m.base_color) m.normal_texture = normals;
  expect_shading_matches_cpu(context, scene);
  const MrCamera camera = camera_at({0.2, -1.5, 1.4}, {0, 0, 0.1}, 64, 48);
  DirRendererVk renderer(context, 64, 48);
  renderer.set_scene(flat, test_options());
  const DifferentialImages before = renderer.render(camera, make_vpls(flat, 64), test_options());
  renderer.set_scene(scene, test_options());
  const DifferentialImages after = renderer.render(camera, make_vpls(scene, 64), test_options());
  int changed = 0, virtual_pixels = 0;
  for (std::size_t i = 0; i < after.real_virtual.size(); ++i) {
    if (after.virtual_coverage.pixels()[i] < 0.5f) continue;
    ++virtual_pixels;
    const float a = luminance(after.real_virtual.pixels()[i]), b = luminance(before.real_virtual.pixels()[i]);
    if (std::abs(a - b) > 0.05f * std::max(a, b)) ++changed;
  }
  EXPECT_GT(changed, virtual_pixels / 3) << "of " << virtual_pixels << " cube pixels";
}

// An emitter VPL's tiles look at the scene from far away (ism.h) and it shades like a
// directional light (vpl.h): both on the GPU as in the CPU mirror.
TEST_F(DirVkTest, EmitterVplSplatsAndShadesLikeTheCpuMirror) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  const MrScene scene = cube_scene_with_emitter();
  const std::vector<Vpl> vpls = make_vpls(scene, 48);
  ASSERT_TRUE(vpls.back().emitter());
  expect_ism_atlas_matches_cpu(context, scene);
  expect_shading_matches_cpu(context, scene);
}

/// The floor + red virtual cube of dir_cpu_test.cpp (no wall): the path tracer's scene.
MrScene open_cube_scene() {
  MrScene scene = test::floor_scene(Eigen::Vector3f::Constant(0.8f), {1.0f, 0.f, 1.5f}, 4.f);
  test::add_virtual_box(scene, synth::Box{{-0.2, -0.2, 0.0}, {0.2, 0.2, 0.4}}, diffuse({0.9f, 0.1f, 0.1f}, "red cube"));
  return scene;
}

TEST_F(DirVkTest, VirtualCubeShadowsAndBleedsOnlyWhereFig57Says) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  const MrScene scene = open_cube_scene();
  const MrCamera camera = camera_at({0.2, -1.5, 1.4}, {0, 0, 0.1}, 48, 36);
  DirRenderOptions options = test_options();
  DirRendererVk renderer(context, 48, 36);
  renderer.set_scene(scene, options);
  const DifferentialImages images = renderer.render(camera, make_vpls(scene, 256), options);
  const auto shadow = test::floor_pixels(scene, camera, {-0.45f, -0.12f}, {-0.25f, 0.12f});
  const auto bleeding = test::floor_pixels(scene, camera, {0.22f, -0.15f}, {0.45f, 0.15f});
  const auto far_floor = test::floor_pixels(scene, camera, {1.2f, -0.6f}, {1.8f, 0.6f});
  ASSERT_GT(shadow.size(), 8u);
  ASSERT_GT(bleeding.size(), 8u);
  ASSERT_GT(far_floor.size(), 8u);
  // The virtual shadow: direct light is gone from L_rv but present in L_r.
  const Eigen::Vector3d shadow_rv = test::mean_over(images.real_virtual, shadow);
  const Eigen::Vector3d shadow_r = test::mean_over(images.real, shadow);
  EXPECT_LT(shadow_rv.sum(), 0.5 * shadow_r.sum());
  // Red bleeding from the virtual cube onto the real floor exists only in L_rv.
  const Eigen::Vector3d bleed = test::mean_over(images.real_virtual, bleeding) - test::mean_over(images.real, bleeding);
  EXPECT_GT(bleed.x(), 0.0);
  EXPECT_GT(bleed.x(), 3.0 * std::abs(bleed.z()));
  // Far from the cube the two worlds agree.
  const Eigen::Vector3d far = test::mean_over(images.real_virtual, far_floor) - test::mean_over(images.real, far_floor);
  EXPECT_LT(far.norm(), 0.02 * test::mean_over(images.real, far_floor).norm());
  // The cube's own pixels: r(p) = 0, so L_r is zero there and L_rv holds the lit red cube.
  int cube_pixels = 0;
  for (std::size_t i = 0; i < images.real.pixels().size(); ++i) {
    if (images.virtual_coverage.pixels()[i] < 0.5f) continue;
    ++cube_pixels;
    EXPECT_EQ(images.real.pixels()[i], (Float3{0.f, 0.f, 0.f}));
  }
  EXPECT_GT(cube_pixels, 20);
}

TEST_F(DirVkTest, DifferentialAgreesWithThePathTracerInShadowAndBleedingRegions) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  const MrScene scene = open_cube_scene();
  const MrCamera camera = test::comparison_camera();
  const DifferentialImages pt = test::reference_images(scene, camera, 1);
  DirRenderOptions options;
  options.shading.min_distance = 0.02f;
  options.shadow_tile = 512;
  options.backend = DirBackend::Gpu;
  DirRendererVk renderer(context, 48, 36);
  renderer.set_scene(scene, options);
  const DifferentialImages dir = renderer.render(camera, make_vpls(scene, 1024), options);
  EXPECT_LT(test::delta_error_on_floor(scene, camera, pt, dir, test::kShadowLo, test::kShadowHi), 0.15) << "shadow region";
  EXPECT_LT(test::delta_error_on_floor(scene, camera, pt, dir, test::kBleedingLo, test::kBleedingHi), 0.15)
      << "bleeding region";
}

TEST_F(DirVkTest, CpuAndGpuBackendsAgreeAndAutoPicksTheCpuOnASoftwareDevice) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  const MrScene scene = cube_scene();
  DirRenderOptions gpu_options = test_options();
  const std::vector<Vpl> vpls = make_vpls(scene, 64);
  const MrCamera camera = camera_at({0.2, -1.5, 1.4}, {0, 0, 0.1}, 64, 48);
  DirRendererVk renderer(context, 64, 48);
  renderer.set_scene(scene, gpu_options);
  const DifferentialImages gpu = renderer.render(camera, vpls, gpu_options);
  EXPECT_FALSE(renderer.last_timings().cpu_shading);
  DirRenderOptions auto_options = gpu_options;
  auto_options.backend = DirBackend::Auto;
  const DifferentialImages automatic = renderer.render(camera, vpls, auto_options);
  EXPECT_EQ(renderer.last_timings().cpu_shading, context.is_cpu_device());
  DirRenderOptions cpu_options = gpu_options;
  cpu_options.backend = DirBackend::Cpu;
  const DifferentialImages cpu = renderer.render(camera, vpls, cpu_options);
  EXPECT_TRUE(renderer.last_timings().cpu_shading);
  int close = 0;
  for (std::size_t i = 0; i < gpu.real.pixels().size(); ++i) {
    const float tolerance = 1e-3f * luminance(cpu.real_virtual.pixels()[i]) + 1e-5f;
    if (length(gpu.real_virtual.pixels()[i] - cpu.real_virtual.pixels()[i]) <= tolerance &&
        length(gpu.real.pixels()[i] - cpu.real.pixels()[i]) <= tolerance)
      ++close;
    EXPECT_EQ(automatic.real.pixels()[i], (context.is_cpu_device() ? cpu : gpu).real.pixels()[i]);
  }
  EXPECT_GT(close, static_cast<int>(gpu.real.pixels().size()) * 98 / 100);
}

// The CPU shading reads the device's G-buffer and shadow atlas in place where the host can map
// them (lavapipe) and through staging copies where it cannot (a discrete GPU; force_staging
// here): both give the same pictures, and the G-buffer images a renderer reuses from frame to
// frame hold nothing of the frame before.
TEST_F(DirVkTest, CpuShadingReadsTheMapsInPlaceOrThroughStagingAlike) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  const MrScene scene = cube_scene();
  DirRenderOptions options = test_options();
  options.backend = DirBackend::Cpu;
  const std::vector<Vpl> vpls = make_vpls(scene, 16);
  const MrCamera camera = camera_at({0.2, -1.5, 1.4}, {0, 0, 0.1}, 64, 48);
  const MrCamera other = camera_at({-0.8, -1.0, 0.6}, {0, 0, 0.2}, 64, 48);
  DirRendererVk mapped(context, 64, 48);
  mapped.set_scene(scene, options);
  const DifferentialImages first = mapped.render(camera, vpls, options);
  const GBuffer first_gbuffer = mapped.last_gbuffer();
  (void)mapped.render(other, vpls, options);
  const DifferentialImages again = mapped.render(camera, vpls, options);
  EXPECT_TRUE(std::ranges::equal(again.real_virtual.pixels(), first.real_virtual.pixels()));
  EXPECT_TRUE(std::ranges::equal(mapped.last_gbuffer().position.pixels(), first_gbuffer.position.pixels()));
  EXPECT_TRUE(std::ranges::equal(mapped.last_gbuffer().material.pixels(), first_gbuffer.material.pixels()));

  auto staging_context = vk::try_create_vulkan({.validation = vk::Validation::On, .force_staging = true});
  ASSERT_NE(staging_context, nullptr);
  DirRendererVk staged(*staging_context, 64, 48);
  staged.set_scene(scene, options);
  const DifferentialImages copied = staged.render(camera, vpls, options);
  EXPECT_TRUE(std::ranges::equal(copied.real_virtual.pixels(), first.real_virtual.pixels()));
  EXPECT_TRUE(std::ranges::equal(copied.real.pixels(), first.real.pixels()));
  EXPECT_EQ(staged.last_shadow_atlas(), mapped.last_shadow_atlas());
  EXPECT_EQ(staging_context->validation_errors(), 0) << staging_context->validation_log()->summary();
}

TEST_F(DirVkTest, RejectsMisuse) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  EXPECT_THROW(DirRendererVk(context, 0, 10), Error);
  DirRendererVk renderer(context, 16, 12);
  const MrCamera camera = camera_at({0.2, -1.5, 1.4}, {0, 0, 0.1}, 16, 12);
  EXPECT_THROW((void)renderer.render(camera, {}), LogicError);
  DirRenderOptions options = test_options();
  renderer.set_scene(open_cube_scene(), options);
  DirRenderOptions other = options;
  other.shadow_tile = 128;
  EXPECT_THROW((void)renderer.render(camera, {}, other), Error);
  EXPECT_THROW((void)renderer.render(camera_at({0.2, -1.5, 1.4}, {0, 0, 0.1}, 32, 24), {}, options), Error);
  other = options;
  other.interleave = 0;
  EXPECT_THROW((void)renderer.render(camera, {}, other), Error);
  IsmOptions too_many;
  too_many.points_per_vpl = 8192;
  EXPECT_THROW((void)sample_ism_points(open_cube_scene(), too_many), Error);
}

}  // namespace
}  // namespace relight::render
