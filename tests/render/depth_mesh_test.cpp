#include "relight/render/scene/depth_mesh.h"

#include <gtest/gtest.h>

#include "relight/core/error.h"
#include "relight/render/reference/ray_tracer.h"
#include "relight/synth/raycast.h"
#include "relight/synth/trajectory.h"

namespace relight::render {
namespace {

TEST(DepthMesh, StepDiscontinuityIsNotBridged) {
  const PinholeIntrinsics k{100, 100, 31.5, 23.5, 64, 48};
  DepthMap depth(64, 48);
  for (int row = 0; row < 48; ++row)
    for (int col = 0; col < 64; ++col) depth(row, col) = col < 32 ? 1.f : 2.f;
  depth(10, 10) = 0.f;  // a hole
  const TriangleMesh mesh = mesh_from_positions(positions_from_depth(depth, k), nullptr, Pose::Identity(), {});
  ASSERT_GT(mesh.triangle_count(), 2000u);
  for (const auto& t : mesh.triangles)
    EXPECT_EQ(mesh.positions[t[0]].z(), mesh.positions[t[1]].z()) << "a triangle spans the step";
  // Two triangles per cell of the 63 x 47 grid, minus the cells across the step and the six
  // triangles (of the diagonal split) that use the hole's vertex.
  EXPECT_EQ(mesh.triangle_count(), 2u * (63u * 47u - 47u) - 6u);
}

TEST(DepthMesh, SyntheticFrameMeshReproducesTheDepthAndTheMaterials) {
  const synth::Scene scene = synth::default_indoor_scene();
  const PinholeIntrinsics k{262.5, 262.5, 159.5, 119.5, 320, 240};
  const Pose pose = synth::look_at({1.5, -1.2, 1.6}, scene.look_at);
  const synth::RenderedFrame frame = synth::render_frame(scene, k, pose);
  MrScene mr;
  DepthMeshMaterials materials;
  materials.labels = &frame.material;
  for (std::uint32_t label = 0; label <= scene.materials.size(); ++label) {
    materials.material_of_label.push_back(mr.add_material({{{}, 0.f, 1.f}, "label " + std::to_string(label), {}}));
  }
  PositionMap positions = positions_from_depth(frame.depth, k);
  mr.meshes.push_back(mesh_from_positions(positions, &frame.normals, pose, materials));
  const RayTracer tracer(mr);
  int valid = 0, hits = 0, close = 0, same_material = 0;
  for (int row = 2; row < 238; row += 3)
    for (int col = 2; col < 318; col += 3) {
      if (!is_valid_depth(frame.depth(row, col))) continue;
      ++valid;
      // A quarter pixel off the centre: a ray through a grid vertex may slip between triangles.
      const Eigen::Vector3d ray = pose.linear() * k.ray(col + 0.25, row + 0.25);
      const auto hit = tracer.intersect(Layer::Real, pose.translation().cast<float>(), ray.normalized().cast<float>());
      if (!hit) continue;
      ++hits;
      const auto exact = synth::intersect(scene, synth::Ray{pose.translation(), ray.normalized()});
      if (exact && std::abs(hit->t - exact->t) < 0.005) ++close;
      if (hit->material == materials.material_of_label[frame.material(row, col)]) ++same_material;
    }
  EXPECT_GT(valid, 7000);
  EXPECT_GT(hits, valid * 98 / 100);
  EXPECT_GT(close, hits * 97 / 100);
  EXPECT_GT(same_material, hits * 95 / 100);
}

TEST(DepthMesh, RejectsMismatchedInputs) {
  const PositionMap positions(8, 8);
  const NormalMap normals(4, 4);
  EXPECT_THROW((void)mesh_from_positions(positions, &normals, Pose::Identity(), {}), Error);
  DepthMeshOptions options;
  options.stride = 0;
  EXPECT_THROW((void)mesh_from_positions(positions, nullptr, Pose::Identity(), {}, options), Error);
}

}  // namespace
}  // namespace relight::render
