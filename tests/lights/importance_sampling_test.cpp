// Hierarchical-warping importance sampling on probes with known answers (CPU reference).
#include "relight/lights/importance_sampling.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "probes.h"
#include "relight/core/error.h"

namespace relight::lights {
namespace {

using test::angle_between;
using test::degrees;
using test::radians;

TEST(ImportanceSampling, SmallEmitterStrongestVplsClusterWithin2Degrees) {
  const ProbeGeometry geometry(ProbeCalibration::centred_fisheye(256, 256), 256, 256);
  const Eigen::Vector3d truth = test::spherical(radians(40), radians(30));
  const RadianceImage probe = test::emitter_probe(geometry, truth, radians(1.0));
  LightSet vpls = sample_importance(probe, geometry, {64, 0});
  ASSERT_EQ(vpls.lights.size(), 64u);
  std::sort(vpls.lights.begin(), vpls.lights.end(),
            [](const Light& a, const Light& b) { return luminance(a.power) > luminance(b.power); });
  // The emitter holds ~99.6 % of the energy: (nearly) every sample lands on it.
  int near = 0;
  for (const Light& light : vpls.lights) near += angle_between(light.direction, truth) < radians(2.0) ? 1 : 0;
  EXPECT_GE(near, 60);
  for (int i = 0; i < 16; ++i) {
    EXPECT_LT(degrees(angle_between(vpls.lights[static_cast<std::size_t>(i)].direction, truth)), 2.0) << "VPL " << i;
  }
}

TEST(ImportanceSampling, UniformFisheyeProbeGivesUniformIrradianceWithin2Percent) {
  const ProbeGeometry geometry(ProbeCalibration::centred_fisheye(128, 128), 128, 128);
  const RadianceImage probe = test::analytic_probe(geometry, [](const Eigen::Vector3d&) {
    return Eigen::Vector3d(1.0, 0.5, 0.25);
  });
  for (const int n : {64, 256}) {
    const LightSet vpls = sample_importance(probe, geometry, {n, 0});
    // Uniform radiance L over the upper hemisphere: E(n) = pi L (1 + cos tilt) / 2.
    for (const double tilt : {0.0, 30.0, 60.0}) {
      const Eigen::Vector3d normal = test::spherical(radians(tilt), radians(20));
      const double expected = std::numbers::pi * (1.0 + std::cos(radians(tilt))) / 2.0;
      const Eigen::Vector3d e = irradiance(vpls, normal);
      EXPECT_NEAR(e.x() / expected, 1.0, 0.02) << "N " << n << " tilt " << tilt;
      EXPECT_NEAR(e.y() / (0.5 * expected), 1.0, 0.02) << "N " << n << " tilt " << tilt;
      EXPECT_NEAR(e.z() / (0.25 * expected), 1.0, 0.02) << "N " << n << " tilt " << tilt;
    }
    // With pdf proportional to radiance every VPL carries the same power, and they add up to
    // the hemisphere's solid angle times L.
    EXPECT_NEAR(total_power(vpls).x() / (2.0 * std::numbers::pi), 1.0, 0.01);
  }
}

TEST(ImportanceSampling, UniformLatLongProbeGivesPiLForEveryNormal) {
  const ProbeGeometry geometry(ProbeCalibration::equirectangular(), 128, 64);
  const RadianceImage probe = test::analytic_probe(geometry, [](const Eigen::Vector3d&) {
    return Eigen::Vector3d::Ones();
  });
  const LightSet vpls = sample_importance(probe, geometry, {256, 0});
  EXPECT_NEAR(total_power(vpls).x() / (4.0 * std::numbers::pi), 1.0, 0.01);
  const std::vector<Eigen::Vector3d> normals{Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0, 0, -1),
                                             Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(1, 1, 1).normalized()};
  for (const Eigen::Vector3d& normal : normals) {
    EXPECT_NEAR(irradiance(vpls, normal).x() / std::numbers::pi, 1.0, 0.02) << normal.transpose();
  }
}

TEST(ImportanceSampling, SyntheticProbeIrradianceOnHorizontalPlaneWithin2Percent) {
  const test::SynthProbe& s = test::default_synth_probe();
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d truth = test::probe_irradiance(s.image, s.geometry, up);
  for (const int n : {64, 256}) {
    const Eigen::Vector3d e = irradiance(sample_importance(s.image, s.geometry, {n, 0}), up);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(e[c] / truth[c], 1.0, 0.02) << "N " << n << " channel " << c;
  }
}

TEST(ImportanceSampling, SyntheticProbeMainLightsMatchSceneWithin3Degrees) {
  const test::SynthProbe& s = test::default_synth_probe();
  for (const int n : {64, 256}) {
    const LightSet vpls = sample_importance(s.image, s.geometry, {n, 0});
    const LightSet clusters = cluster_lights(vpls, radians(5));
    ASSERT_GE(clusters.lights.size(), 2u);
    // Every VPL carries W/N of luminance, so a cluster's power counts the samples that landed on
    // the light: stratification keeps that count within a few samples of N * the light's share.
    const double one_vpl = luminance(total_power(vpls)) / n;
    // scene.lights[0] (6 W/sr at 1.56 m) is the brighter one at the probe.
    for (std::size_t i = 0; i < 2; ++i) {
      const Eigen::Vector3d truth = test::light_direction(s, s.scene.lights[i]);
      EXPECT_LT(degrees(angle_between(clusters.lights[i].direction, truth)), 3.0) << "N " << n << " light " << i;
      const double true_irradiance = luminance(test::light_irradiance(s, s.scene.lights[i]));
      EXPECT_NEAR(luminance(clusters.lights[i].power), true_irradiance, 3.0 * one_vpl) << "N " << n << " light " << i;
    }
  }
}

TEST(ImportanceSampling, SameSeedSameLightsOtherSeedOtherPoints) {
  const test::SynthProbe& s = test::default_synth_probe();
  std::vector<WarpedSample> a, b, c;
  ImportancePyramid pyramid;
  (void)sample_importance(s.image, s.geometry, {64, 7}, pyramid, &a);
  (void)sample_importance(s.image, s.geometry, {64, 7}, pyramid, &b);
  (void)sample_importance(s.image, s.geometry, {64, 8}, pyramid, &c);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
}

TEST(ImportanceSampling, PyramidTopIsTheSumOfAllImportance) {
  const test::SynthProbe& s = test::default_synth_probe();
  ImportancePyramid pyramid;
  pyramid.build(s.image, s.geometry);
  EXPECT_EQ(pyramid.levels(), 8);
  double sum = 0.0;
  for (int row = 0; row < 256; ++row) {
    for (int col = 0; col < 256; ++col) sum += pixel_importance(s.image(row, col), s.geometry.solid_angle(row, col));
  }
  EXPECT_NEAR(pyramid.total() / sum, 1.0, 1e-5);
}

TEST(ImportanceSampling, HammersleyPointsAreStratified) {
  // Every one of the 8x8 cells of [0,1)^2 holds exactly one of 64 points (a (0,2)-net property
  // that rotation by the seed keeps for the rows, not for the cells; so seed 0 here).
  std::vector<int> cells(64, 0);
  for (std::uint32_t i = 0; i < 64; ++i) {
    const auto p = hammersley_point(i, 1.f / 64.f, 0.f, 0.f);
    ++cells[static_cast<std::size_t>(static_cast<int>(p[1] * 8) * 8 + static_cast<int>(p[0] * 8))];
  }
  EXPECT_TRUE(std::all_of(cells.begin(), cells.end(), [](int count) { return count == 1; }));
}

// Hammersley's 256 points form a (0, 8, 2)-net in base 2: every box of 1/2^a x 1/2^(8 - a) holds
// exactly one point. The rotation moves the set without breaking that (modulo 1), and every
// point stays in the unit square (DIR's caustic photons take their directions from it too).
TEST(ImportanceSampling, RotatedHammersleyIsANetInEveryShapeOfBox) {
  const std::array<float, 2> shift{0.37f, 0.81f};
  constexpr std::uint32_t kCount = 256;
  for (int a = 0; a <= 8; ++a) {
    const int nx = 1 << a, ny = kCount / nx;
    std::vector<int> boxes(static_cast<std::size_t>(nx * ny), 0);
    for (std::uint32_t i = 0; i < kCount; ++i) {
      const auto p = hammersley_point(i, 1.f / static_cast<float>(kCount), shift[0], shift[1]);
      ASSERT_GE(p[0], 0.f);
      ASSERT_LT(p[0], 1.f);
      ASSERT_GE(p[1], 0.f);
      ASSERT_LT(p[1], 1.f);
      const auto back = [](float value, float by) { return value - by < 0.f ? value - by + 1.f : value - by; };
      const float u = back(p[0], shift[0]), v = back(p[1], shift[1]);
      // A hair inside, against float rounding of the shift at a box's edge.
      const int x = std::min(nx - 1, static_cast<int>(std::floor((u + 1e-6f) * static_cast<float>(nx))));
      const int y = std::min(ny - 1, static_cast<int>(std::floor((v + 1e-6f) * static_cast<float>(ny))));
      ++boxes[static_cast<std::size_t>(y) * static_cast<std::size_t>(nx) + static_cast<std::size_t>(x)];
    }
    for (const int count : boxes) ASSERT_EQ(count, 1) << nx << " x " << ny << " boxes";
  }
}

TEST(ImportanceSampling, BadInputIsAnError) {
  const ProbeGeometry geometry(ProbeCalibration::centred_fisheye(32, 32), 32, 32);
  EXPECT_THROW((void)sample_importance(RadianceImage(32, 32), geometry, {16, 0}), Error);  // black
  EXPECT_THROW((void)sample_importance(RadianceImage(16, 32, {1, 1, 1}), geometry, {16, 0}), Error);
  EXPECT_THROW((void)sample_importance(RadianceImage(32, 32, {1, 1, 1}), geometry, {0, 0}), Error);
}

}  // namespace
}  // namespace relight::lights
