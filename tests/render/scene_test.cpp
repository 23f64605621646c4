#include <gtest/gtest.h>

#include <cmath>

#include "relight/core/error.h"
#include "relight/render/reference/ray_tracer.h"
#include "relight/truth/scene_from_synth.h"
#include "relight/synth/raycast.h"
#include "relight/synth/trajectory.h"

namespace relight::render {
namespace {

TEST(Tessellation, SphereVerticesLieOnTheSphereAndNormalsPointOut) {
  const synth::Sphere sphere{{1, 2, 3}, 0.5};
  const TriangleMesh mesh = truth::tessellate(sphere, 0);
  ASSERT_EQ(mesh.normals.size(), mesh.positions.size());
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    const Eigen::Vector3f offset = mesh.positions[i] - Eigen::Vector3f(1, 2, 3);
    EXPECT_NEAR(offset.norm(), 0.5f, 1e-5f);
    EXPECT_GT(offset.normalized().dot(mesh.normals[i]), 0.9999f);
  }
}

TEST(Tessellation, BoxHasTwelveTrianglesWithOutwardNormals) {
  const TriangleMesh mesh = truth::tessellate(synth::Box{{0, 0, 0}, {1, 2, 3}}, 4);
  ASSERT_EQ(mesh.triangle_count(), 12u);
  const Eigen::Vector3f centre(0.5f, 1.f, 1.5f);
  for (std::size_t i = 0; i < mesh.positions.size(); ++i)
    EXPECT_GT((mesh.positions[i] - centre).dot(mesh.normals[i]), 0.f);
  for (std::uint32_t m : mesh.triangle_material) EXPECT_EQ(m, 4u);
}

TEST(Tessellation, RejectsTooFewSegments) {
  EXPECT_THROW((void)truth::tessellate(synth::Sphere{{0, 0, 0}, 1}, 0, {2}), Error);
}

TEST(MrSceneValidation, NamesTheBrokenMesh) {
  MrScene scene;
  scene.add_material({});
  TriangleMesh mesh;
  mesh.name = "broken";
  mesh.positions = {{0, 0, 0}, {1, 0, 0}};
  mesh.triangles = {{0, 1, 2}};
  mesh.triangle_material = {0};
  scene.meshes.push_back(mesh);
  try {
    scene.validate();
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("broken"), std::string::npos);
  }
}

TEST(RayTracer, TessellatedSyntheticSceneMatchesTheAnalyticDepth) {
  const synth::Scene synthetic = synth::default_indoor_scene();
  const MrScene scene = truth::scene_from_synth(synthetic);
  const RayTracer tracer(scene);
  const Pose pose = synth::look_at({1.6, -1.4, 1.5}, synthetic.look_at);
  const PinholeIntrinsics k{};
  const Eigen::Vector3f origin = pose.translation().cast<float>();
  int compared = 0, close = 0;
  for (int row = 5; row < 480; row += 13)
    for (int col = 5; col < 640; col += 13) {
      const Eigen::Vector3d d = (pose.linear() * k.ray(col, row).normalized());
      const auto expected = synth::intersect(synthetic, synth::Ray{pose.translation(), d});
      const auto hit = tracer.intersect(Layer::Real, origin, d.cast<float>());
      ASSERT_EQ(expected.has_value(), hit.has_value()) << row << "," << col;
      if (!hit) continue;
      ++compared;
      if (std::abs(hit->t - expected->t) < 2e-3) ++close;
      EXPECT_TRUE(hit->real);
    }
  // Silhouettes of the tessellated curved objects may differ by a pixel; everywhere else the
  // distances agree to 2 mm.
  EXPECT_GT(compared, 1500);
  EXPECT_GE(close, compared - 5);
}

TEST(RayTracer, VirtualLayerIsSeparateFromTheRealLayer) {
  MrScene scene;
  scene.add_material({});
  TriangleMesh floor = truth::tessellate(synth::Rect{{0, 0, 0}, {0, 0, 1}, {1, 0, 0}, {0, 1, 0}, 1, 1}, 0);
  TriangleMesh cube = truth::tessellate(synth::Box{{-0.1, -0.1, 0.5}, {0.1, 0.1, 0.7}}, 0);
  cube.real = false;
  scene.meshes = {floor, cube};
  const RayTracer tracer(scene);
  const Eigen::Vector3f origin(0, 0, 2), down(0, 0, -1);
  EXPECT_NEAR(tracer.intersect(Layer::Real, origin, down)->t, 2.f, 1e-5f);
  const auto hit = tracer.intersect(Layer::Virtual, origin, down);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t, 1.3f, 1e-5f);
  EXPECT_FALSE(hit->real);
  EXPECT_TRUE(tracer.occluded(Layer::Virtual, origin, down, 1.5f));
  EXPECT_FALSE(tracer.occluded(Layer::Virtual, origin, down, 1.2f));
  EXPECT_FALSE(tracer.occluded(Layer::Real, origin, down, 1.9f));
}

}  // namespace
}  // namespace relight::render
