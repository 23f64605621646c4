// Merging a probe's many directional lights into a few (merge_lights.h): energy kept, clusters
// found, irradiance nearly unchanged, point lights and the real/virtual split untouched.
#include "relight/lights/merge_lights.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

namespace relight::lights {
namespace {

Light directional(const Eigen::Vector3d& towards, double power, bool real = true) {
  Light light;
  light.direction = towards.normalized();
  light.power = Eigen::Vector3d::Constant(power);
  light.real = real;
  return light;
}

/// 16 lights within 5 degrees of each of four directions, as importance sampling a probe with
/// four bright windows gives.
LightSet four_windows() {
  LightSet set;
  std::mt19937 rng(3);
  std::normal_distribution<double> jitter(0.0, 0.04);
  const Eigen::Vector3d windows[] = {{1, 0, 1}, {-1, 0.5, 1}, {0, -1, 0.6}, {0.2, 1, 0.3}};
  for (const Eigen::Vector3d& window : windows)
    for (int i = 0; i < 16; ++i)
      set.lights.push_back(
          directional(window.normalized() + Eigen::Vector3d(jitter(rng), jitter(rng), jitter(rng)), 0.1));
  return set;
}

TEST(MergeLights, ASetWithinTheLimitComesBackAsItIs) {
  const LightSet set = four_windows();
  const LightSet same = merge_directional_lights(set, 64);
  ASSERT_EQ(same.lights.size(), set.lights.size());
  for (std::size_t i = 0; i < set.lights.size(); ++i) EXPECT_EQ(same.lights[i].direction, set.lights[i].direction);
}

TEST(MergeLights, ManySamplesBecomeTheirClustersWithTheirEnergyAndIrradiance) {
  const LightSet set = four_windows();
  const LightSet merged = merge_directional_lights(set, 4);
  ASSERT_EQ(merged.lights.size(), 4u);
  EXPECT_TRUE(total_power(merged).isApprox(total_power(set), 1e-12)) << "the energy stays";
  for (const Light& light : merged.lights) {
    EXPECT_NEAR(light.power.x(), 1.6, 1e-9) << "one window's 16 samples each";
    EXPECT_NEAR(light.direction.norm(), 1.0, 1e-12);
  }
  // Irradiance on a few normals: within 1 % of the 64 samples'.
  for (const Eigen::Vector3d& normal : {Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(1, 0, 0.2).normalized(),
                                        Eigen::Vector3d(-0.3, -0.8, 0.5).normalized()}) {
    const double before = irradiance(set, normal).x(), after = irradiance(merged, normal).x();
    EXPECT_NEAR(after, before, 0.01 * before) << normal.transpose();
  }
}

TEST(MergeLights, PointLightsAndTheRealVirtualSplitStay) {
  LightSet set = four_windows();
  Light lamp;
  lamp.kind = LightKind::Point;
  lamp.position = {0.5, 0.2, 2.0};
  lamp.power = Eigen::Vector3d::Constant(3.0);
  set.lights.insert(set.lights.begin() + 5, lamp);
  set.lights.push_back(directional({0, 0, 1}, 0.5, false));
  set.lights.push_back(directional({0, 0.1, 1}, 0.5, false));
  const LightSet merged = merge_directional_lights(set, 1);
  ASSERT_EQ(merged.lights.size(), 3u);
  EXPECT_EQ(merged.lights[0].kind, LightKind::Point);
  EXPECT_EQ(merged.lights[0].position, lamp.position);
  EXPECT_TRUE(merged.lights[1].real);
  EXPECT_NEAR(merged.lights[1].power.x(), 6.4, 1e-9);
  EXPECT_FALSE(merged.lights[2].real);
  EXPECT_NEAR(merged.lights[2].power.x(), 1.0, 1e-12);
  EXPECT_NEAR(merged.lights[2].direction.y(), std::sin(std::atan(0.1) / 2), 1e-3) << "halfway between its two";
}

// merge_close_directional_lights: the samples of each window (within 5 degrees of it) merge; the
// windows, 40 degrees and more apart, stay four lights; with no angle the set is as it was.
TEST(MergeLights, CloseLightsMergeByAngleAndDistantOnesStay) {
  const LightSet set = four_windows();
  const LightSet merged = merge_close_directional_lights(set, 15.0);
  ASSERT_EQ(merged.lights.size(), 4u);
  EXPECT_TRUE(total_power(merged).isApprox(total_power(set), 1e-12)) << "the energy stays";
  for (const Light& light : merged.lights) EXPECT_NEAR(light.power.x(), 1.6, 1e-9);
  EXPECT_EQ(merge_close_directional_lights(set, 0.0).lights.size(), set.lights.size());
  // Two lights 3 degrees apart merge at 5 degrees and stay two at 2.
  LightSet pair;
  pair.lights.push_back(directional({0, 0, 1}, 1.0));
  pair.lights.push_back(
      directional({std::sin(3.0 * std::numbers::pi / 180.0), 0, std::cos(3.0 * std::numbers::pi / 180.0)}, 1.0));
  EXPECT_EQ(merge_close_directional_lights(pair, 5.0).lights.size(), 1u);
  EXPECT_EQ(merge_close_directional_lights(pair, 2.0).lights.size(), 2u);
}

}  // namespace
}  // namespace relight::lights
