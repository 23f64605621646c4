// Median cut (Debevec 2005) on probes with known answers.
#include "relight/lights/median_cut.h"

#include <gtest/gtest.h>

#include "probes.h"
#include "relight/core/error.h"

namespace relight::lights {
namespace {

using test::angle_between;
using test::degrees;
using test::radians;

TEST(MedianCut, PowersAddUpToTheProbeIntegralAndRegionsHaveEqualEnergy) {
  const test::SynthProbe& s = test::default_synth_probe();
  const LightSet lights = median_cut(s.image, s.geometry, {64});
  ASSERT_EQ(lights.lights.size(), 64u);
  Eigen::Vector3d integral = Eigen::Vector3d::Zero();
  for (int row = 0; row < s.image.height(); ++row) {
    for (int col = 0; col < s.image.width(); ++col) {
      const Float3& l = s.image(row, col);
      integral += s.geometry.solid_angle(row, col) * Eigen::Vector3d(l.x, l.y, l.z);
    }
  }
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(total_power(lights)[c] / integral[c], 1.0, 1e-6);
  // Irradiance on the horizontal plane: lights at region centroids approximate the integral.
  const Eigen::Vector3d truth = test::probe_irradiance(s.image, s.geometry, Eigen::Vector3d::UnitZ());
  EXPECT_NEAR(luminance(irradiance(lights, Eigen::Vector3d::UnitZ())) / luminance(truth), 1.0, 0.02);
}

TEST(MedianCut, SmallEmitterGetsLightsWithin2Degrees) {
  const ProbeGeometry geometry(ProbeCalibration::centred_fisheye(256, 256), 256, 256);
  const Eigen::Vector3d truth = test::spherical(radians(55), radians(-120));
  const RadianceImage probe = test::emitter_probe(geometry, truth, radians(1.0));
  const LightSet clusters = cluster_lights(median_cut(probe, geometry, {16}), radians(5));
  EXPECT_LT(degrees(angle_between(clusters.lights.front().direction, truth)), 2.0);
}

TEST(MedianCut, SyntheticProbeMainLightsMatchSceneWithin3Degrees) {
  const test::SynthProbe& s = test::default_synth_probe();
  const LightSet clusters = cluster_lights(median_cut(s.image, s.geometry, {64}), radians(5));
  ASSERT_GE(clusters.lights.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    const Eigen::Vector3d truth = test::light_direction(s, s.scene.lights[i]);
    EXPECT_LT(degrees(angle_between(clusters.lights[i].direction, truth)), 3.0) << "light " << i;
  }
}

TEST(MedianCut, LatLongUniformProbeIsBalanced) {
  const ProbeGeometry geometry(ProbeCalibration::equirectangular(), 128, 64);
  const RadianceImage probe = test::analytic_probe(geometry, [](const Eigen::Vector3d&) {
    return Eigen::Vector3d::Ones();
  });
  const LightSet lights = median_cut(probe, geometry, {32});
  ASSERT_EQ(lights.lights.size(), 32u);
  EXPECT_NEAR(total_power(lights).x() / (4.0 * std::numbers::pi), 1.0, 1e-3);  // midpoint-rule sin(theta)
  EXPECT_NEAR(irradiance(lights, Eigen::Vector3d::UnitZ()).x() / std::numbers::pi, 1.0, 0.05);
}

TEST(MedianCut, BlackProbeIsAnError) {
  const ProbeGeometry geometry(ProbeCalibration::centred_fisheye(32, 32), 32, 32);
  EXPECT_THROW((void)median_cut(RadianceImage(32, 32), geometry, {8}), Error);
}

}  // namespace
}  // namespace relight::lights
