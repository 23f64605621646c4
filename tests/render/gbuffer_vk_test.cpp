// The rasterised G-buffer against the ray-cast reference on the synthetic scene with the
// shipped pebble: same surface, flag and material at every pixel away from triangle edges.
#include "relight/render/dir/gbuffer_vk.h"

#include <gtest/gtest.h>

#include "relight/core/error.h"
#include "relight/render/scene/normal_map.h"
#include "relight/synth/trajectory.h"
#include "relight/vk/context.h"
#include "support/vulkan_test_env.h"
#include "test_scenes.h"

namespace relight::render {
namespace {

class GBufferVkTest : public relight::test::VulkanTest {};

TEST_F(GBufferVkTest, MatchesTheRayCastGBuffer) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  const MrScene scene = test::indoor_with_pebble();
  const MrCamera camera = test::camera_at({1.3, -1.1, 1.4}, {0.2, -0.1, 0.75}, 160, 120);
  GBufferVk renderer(context, 160, 120);
  renderer.set_scene(scene);
  const GBuffer gpu = renderer.render(camera);
  const GBuffer cpu = gbuffer_cpu(RayTracer(scene), camera);
  int both = 0, same_surface = 0, virtual_pixels = 0, coverage_mismatch = 0;
  for (int row = 0; row < 120; ++row)
    for (int col = 0; col < 160; ++col) {
      const bool seen_gpu = gpu.material(row, col) != 0, seen_cpu = cpu.material(row, col) != 0;
      if (seen_gpu != seen_cpu) {
        ++coverage_mismatch;
        continue;
      }
      if (!seen_gpu) continue;
      ++both;
      virtual_pixels += cpu.virtual_surface(row, col);
      if (gpu.material(row, col) != cpu.material(row, col) || gpu.virtual_surface(row, col) != cpu.virtual_surface(row, col))
        continue;  // an edge between two objects
      ++same_surface;
      EXPECT_NEAR(gpu.distance(row, col), cpu.distance(row, col), 1e-3f * cpu.distance(row, col) + 1e-4f) << row << "," << col;
      EXPECT_GT(dot(gpu.normal(row, col), cpu.normal(row, col)), 0.999f) << row << "," << col;
      EXPECT_LT(length(gpu.position(row, col) - cpu.position(row, col)), 2e-3f * cpu.distance(row, col)) << row << "," << col;
    }
  EXPECT_GT(both, 160 * 120 * 9 / 10);
  EXPECT_GT(virtual_pixels, 30) << "the pebble is in view";
  EXPECT_GT(same_surface, both * 99 / 100);
  EXPECT_LT(coverage_mismatch, 160 * 120 / 100);
  if (context.timestamps_supported()) {
    EXPECT_GT(renderer.last_gpu_ms(), 0.0);
  }
}

// Texture coordinates, footprints and tangent frames: the rasteriser's interpolation and screen
// derivatives against the ray tracer's barycentrics, ray differentials and gradients.
TEST_F(GBufferVkTest, TextureCoordinatesMatchTheRayDifferentials) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  MrScene scene = test::indoor_with_pebble();
  test::texture_virtual_meshes(scene);
  const MrCamera camera = test::camera_at({0.9, -0.7, 1.1}, {0.35, -0.2, 0.8}, 160, 120);
  GBufferVk renderer(context, 160, 120);
  renderer.set_scene(scene);
  const GBuffer gpu = renderer.render(camera);
  const GBuffer cpu = gbuffer_cpu(RayTracer(scene), camera);
  ASSERT_FALSE(cpu.texcoord.empty());
  int compared = 0, close_footprint = 0, close_frame = 0;
  for (int row = 1; row < 119; ++row)
    for (int col = 1; col < 159; ++col) {
      if (!cpu.virtual_surface(row, col) || !gpu.virtual_surface(row, col)) continue;
      if (cpu.material(row, col) != gpu.material(row, col) || gpu.texcoord(row, col).z == 0.f) continue;
      ++compared;
      const Float3 &g = gpu.texcoord(row, col), &c = cpu.texcoord(row, col);
      EXPECT_NEAR(g.x, c.x, 5e-3f) << row << "," << col;
      EXPECT_NEAR(g.y, c.y, 5e-3f) << row << "," << col;
      // dFdx differences within a 2x2 quad against differentials to the next pixel: close, not
      // equal, and on a curved surface the neighbour's ray meets another triangle.
      if (std::abs(g.z - c.z) <= 0.25f * c.z) ++close_footprint;
      // The tangent frame: the triangle's, from screen derivatives against the hit's gradient.
      const Float3 &gn = gpu.normal(row, col), &cn = cpu.normal(row, col);
      const auto gf = decode_tangent(gpu.tangent(row, col), Eigen::Vector3f(gn.x, gn.y, gn.z));
      const auto cf = decode_tangent(cpu.tangent(row, col), Eigen::Vector3f(cn.x, cn.y, cn.z));
      if (gf && cf && gf->handedness == cf->handedness && gf->tangent.dot(cf->tangent) > 0.995f) ++close_frame;
    }
  ASSERT_GT(compared, 300) << "the pebble fills part of the view";
  EXPECT_GT(close_footprint, compared * 9 / 10);
  EXPECT_GT(close_frame, compared * 95 / 100);
  for (std::size_t i = 0; i < cpu.texcoord.size(); ++i) {
    if (!cpu.virtual_surface.pixels()[i]) {
      EXPECT_EQ(cpu.texcoord.pixels()[i].z, 0.f) << "real surfaces have no coordinates";
    }
  }
}

// The draw is indexed and a triangle takes the material of its first corner (mesh_raster_vk.h):
// a fan whose four triangles start at one shared vertex with four materials, and a mesh without
// vertex normals (face normals on corners of its own), come out as the ray-cast G-buffer has them.
TEST_F(GBufferVkTest, TrianglesThatShareTheirFirstCornerKeepTheirOwnMaterials) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  MrScene scene;
  TriangleMesh fan;  // a square on z = 0 around its centre vertex 0, each quarter its own material
  fan.positions = {{0.f, 0.f, 0.f}, {-0.5f, -0.5f, 0.f}, {0.5f, -0.5f, 0.f}, {0.5f, 0.5f, 0.f}, {-0.5f, 0.5f, 0.f}};
  fan.normals.assign(fan.positions.size(), Eigen::Vector3f::UnitZ());
  for (std::uint32_t quarter = 0; quarter < 4; ++quarter) {
    fan.triangles.push_back({0u, 1u + quarter, 1u + (quarter + 1) % 4});
    fan.triangle_material.push_back(scene.add_material({}));
  }
  TriangleMesh tent;  // two faces meeting on a ridge above the fan, no vertex normals
  tent.positions = {{-0.2f, -0.1f, 0.1f}, {0.2f, -0.1f, 0.1f}, {0.2f, 0.f, 0.2f},
                    {-0.2f, 0.f, 0.2f},   {-0.2f, 0.1f, 0.1f}, {0.2f, 0.1f, 0.1f}};
  tent.triangles = {{0, 1, 2}, {0, 2, 3}, {3, 2, 5}, {3, 5, 4}};
  tent.triangle_material.assign(4, scene.add_material({}));
  tent.real = false;
  scene.meshes = {fan, tent};
  const MrCamera camera = test::camera_at({0.05, -0.6, 1.2}, {0.0, 0.0, 0.0}, 80, 60);
  GBufferVk renderer(context, 80, 60);
  renderer.set_scene(scene);
  const GBuffer gpu = renderer.render(camera);
  const GBuffer cpu = gbuffer_cpu(RayTracer(scene), camera);
  std::vector<int> seen(scene.materials.size() + 1, 0);
  int compared = 0, same = 0;
  for (int row = 0; row < 60; ++row)
    for (int col = 0; col < 80; ++col) {
      if (cpu.material(row, col) == 0) continue;
      ++compared;
      ++seen[cpu.material(row, col)];
      if (gpu.material(row, col) != cpu.material(row, col)) continue;  // an edge between two triangles
      ++same;
      EXPECT_GT(dot(gpu.normal(row, col), cpu.normal(row, col)), 0.999f) << row << "," << col;
    }
  for (std::size_t label = 1; label < seen.size(); ++label) EXPECT_GT(seen[label], 20) << "material " << label - 1;
  EXPECT_GT(same, compared * 95 / 100);
}

TEST_F(GBufferVkTest, RejectsAWrongCameraSizeAndRenderBeforeScene) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  GBufferVk renderer(context, 32, 24);
  const MrCamera camera = test::camera_at({0, -2, 1}, {0, 0, 0}, 32, 24);
  EXPECT_THROW((void)renderer.render(camera), LogicError);
  renderer.set_scene(test::floor_scene(Eigen::Vector3f::Constant(0.5f), {0, 0, 2}, 1.f));
  EXPECT_THROW((void)renderer.render(test::camera_at({0, -2, 1}, {0, 0, 0}, 64, 48)), Error);
  const GBuffer g = renderer.render(camera);
  EXPECT_NE(g.material(12, 16), 0);
}

}  // namespace
}  // namespace relight::render
