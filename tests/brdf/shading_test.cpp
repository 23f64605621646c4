// The estimation model (shading.h) reproduces the synthetic renderer's radiance from the exact
// geometry, materials and lights, so that fitting it to synthetic images can recover the truth.
#include "relight/brdf/shading.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <numbers>

#include "brdf_test_scene.h"

namespace relight::brdf {
namespace {

TEST(Shading, PhongModelReproducesTheSyntheticRadianceOnLitPixels) {
  const test::BrdfScene& s = test::brdf_scene();
  int compared = 0;
  double worst = 0.0;
  for (int r = 0; r < s.intrinsics.height; r += 3) {
    for (int c = 0; c < s.intrinsics.width; c += 3) {
      const int id = s.truth.material(r, c);
      if (id == 0 || s.shadowed(r, c)) continue;
      const synth::Material& m = s.scene.materials[static_cast<std::size_t>(id - 1)];
      const Float3 p = s.positions(r, c), n = s.truth.normals(r, c), kd = s.truth.albedo(r, c);
      const Eigen::Vector3f model = phong_radiance(s.lights, {p.x, p.y, p.z}, {n.x, n.y, n.z}, {kd.x, kd.y, kd.z},
                                                   static_cast<float>(m.ks), static_cast<float>(m.n));
      const Float3 truth = s.truth.radiance(r, c);
      const Eigen::Vector3f t{truth.x, truth.y, truth.z};
      worst = std::max(worst, static_cast<double>((model - t).cwiseAbs().maxCoeff() / std::max(1.f, t.maxCoeff())));
      ++compared;
    }
  }
  EXPECT_GT(compared, 10000);
  EXPECT_LT(worst, 2e-3);  // float against double (relative where the radiance exceeds 1)
}

TEST(Shading, DiffuseShadingMatchesTheGroundTruthSplit) {
  const test::BrdfScene& s = test::brdf_scene();
  const int r = s.intrinsics.height / 2, c = s.intrinsics.width / 2;
  ASSERT_NE(s.truth.material(r, c), 0);
  const Float3 p = s.positions(r, c), n = s.truth.normals(r, c), kd = s.truth.albedo(r, c);
  const Eigen::Vector3f d = diffuse_shading(s.lights, {p.x, p.y, p.z}, {n.x, n.y, n.z});
  ASSERT_EQ(s.shadowed(r, c), 0);
  EXPECT_NEAR(kd.x * d.x(), s.diffuse(r, c).x, 1e-4f);
}

TEST(Shading, ASpotLightsOnlyItsCone) {
  lights::LightSet set;
  lights::Light spot;
  spot.kind = lights::LightKind::Spot;
  spot.position = {0, 0, 2};
  spot.axis = {0, 0, -1};
  spot.cone_degrees = 20;
  spot.inner_degrees = 16;
  spot.power = {4, 4, 4};
  set.lights.push_back(spot);
  const ShadingLights lights = to_camera_frame(set, Pose::Identity());
  const Eigen::Vector3f up = Eigen::Vector3f::UnitZ();
  // On its axis, 2 m below: E = I / d^2 (cosine 1); 45 degrees off the axis: nothing.
  EXPECT_NEAR(diffuse_shading(lights, {0, 0, 0}, up).x(), 1.f / std::numbers::pi_v<float>, 1e-6f);
  EXPECT_EQ(diffuse_shading(lights, {2, 0, 0}, up).x(), 0.f);
  // The camera frame turns the axis with the positions: the same point lit the same way.
  Pose camera_to_world = Pose::Identity();
  camera_to_world.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const ShadingLights turned = to_camera_frame(set, camera_to_world);
  const Eigen::Vector3f origin = (camera_to_world.inverse() * Eigen::Vector3d::Zero()).cast<float>();
  const Eigen::Vector3f normal = (camera_to_world.inverse().linear() * Eigen::Vector3d::UnitZ()).cast<float>();
  EXPECT_NEAR(diffuse_shading(turned, origin, normal).x(), 1.f / std::numbers::pi_v<float>, 1e-5f);
}

TEST(Shading, LinearizeInvertsTheSrgbEncoding) {
  EXPECT_FLOAT_EQ(srgb8_to_linear(0), 0.f);
  EXPECT_FLOAT_EQ(srgb8_to_linear(255), 1.f);
  EXPECT_NEAR(srgb8_to_linear(128), 0.2158605f, 1e-6f);
  ColorImage image(2, 1, Rgb8{255, 0, 128});
  const RadianceImage linear = linearize(image);
  EXPECT_FLOAT_EQ(linear(0, 1).x, 1.f);
  EXPECT_FLOAT_EQ(linear(0, 1).y, 0.f);
}

}  // namespace
}  // namespace relight::brdf
