#include "relight/synth/probe.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace relight::synth {
namespace {

using Eigen::Vector3d;

struct ProbeFixture {
  Scene scene = default_indoor_scene();
  LightProbe probe = default_probe(scene);
  RadianceImage image = render_probe(scene, probe, 0);

  [[nodiscard]] Eigen::Vector2d pixel_of(const Vector3d& world_point) const {
    return *probe.camera.project(probe.probe_to_world.transpose() * (world_point - probe.position));
  }
};

const ProbeFixture& fixture() {
  static const ProbeFixture f;
  return f;
}

TEST(Probe, BrightestPixelsLieInTheDirectionOfTheLights) {
  const ProbeFixture& f = fixture();
  std::vector<std::pair<double, int>> ranked;
  for (std::size_t i = 0; i < f.image.size(); ++i) ranked.push_back({luminance(f.image.pixels()[i]), static_cast<int>(i)});
  std::sort(ranked.rbegin(), ranked.rend());
  std::vector<bool> seen(f.scene.lights.size(), false);
  for (std::size_t k = 0; k < 50; ++k) {
    const int row = ranked[k].second / f.image.width(), col = ranked[k].second % f.image.width();
    double nearest = 1e9;
    std::size_t which = 0;
    for (std::size_t l = 0; l < f.scene.lights.size(); ++l) {
      const double distance = (f.pixel_of(f.scene.lights[l].position) - Eigen::Vector2d(col, row)).norm();
      if (distance < nearest) nearest = distance, which = l;
    }
    EXPECT_LT(nearest, 12.0) << "bright pixel " << row << "," << col << " is not at a light";
    seen[which] = true;
  }
  EXPECT_TRUE(seen[0]);  // the strongest light dominates the top 50 pixels
  for (const PointLight& light : f.scene.lights) {
    const Eigen::Vector2d px = f.pixel_of(light.position);
    const Float3 centre = f.image(static_cast<int>(std::lround(px.y())), static_cast<int>(std::lround(px.x())));
    const double expected = light.colour.y() * light.intensity / (std::numbers::pi * light.radius * light.radius);
    EXPECT_NEAR(centre.y, expected, 1e-3 * expected);
  }
}

// Summing radiance times pixel solid angle over a light's disc gives its irradiance I / d^2 at
// the probe (for a light near the optical axis the disc is almost undistorted).
TEST(Probe, IntegratedDiscCarriesTheLightsIntensity) {
  const ProbeFixture& f = fixture();
  for (const PointLight& light : f.scene.lights) {
    const Eigen::Vector2d px = f.pixel_of(light.position);
    double irradiance = 0.0;
    for (int row = static_cast<int>(px.y()) - 25; row <= static_cast<int>(px.y()) + 25; ++row) {
      for (int col = static_cast<int>(px.x()) - 25; col <= static_cast<int>(px.x()) + 25; ++col) {
        if (!f.image.in_bounds(row, col)) continue;
        const double value = f.image(row, col).y - f.scene.environment.y();
        irradiance += value * f.probe.camera.pixel_solid_angle(col, row);
      }
    }
    const double expected = light.colour.y() * light.intensity / (light.position - f.probe.position).squaredNorm();
    EXPECT_NEAR(irradiance, expected, 0.05 * expected);
  }
}

TEST(Probe, ZenithShowsTheEnvironmentAndOutsideTheCircleIsZero) {
  const ProbeFixture& f = fixture();
  const Float3 zenith = f.image(256, 256);
  EXPECT_FLOAT_EQ(zenith.x, static_cast<float>(f.scene.environment.x()));
  EXPECT_EQ(f.image(0, 0), Float3{});
  EXPECT_EQ(f.image(511, 511), Float3{});
}

TEST(ProbeNoise, IsNewEveryFrameReproducibleAndUnbiased) {
  RadianceImage clean(64, 64, Float3{1.f, 0.5f, 0.25f});
  const auto same = [](const RadianceImage& x, const RadianceImage& y) {
    return std::ranges::equal(x.pixels(), y.pixels());
  };
  const RadianceImage a = add_probe_noise(clean, 0.2, 7, 3);
  EXPECT_TRUE(same(a, add_probe_noise(clean, 0.2, 7, 3)));   // same seed and frame
  EXPECT_FALSE(same(a, add_probe_noise(clean, 0.2, 7, 4)));  // a new frame, new noise
  EXPECT_TRUE(same(add_probe_noise(clean, 0.0, 7, 3), clean));
  double sum = 0.0, square = 0.0;
  for (const Float3& p : a.pixels()) {
    sum += p.x;
    square += p.x * p.x;
  }
  const double n = static_cast<double>(a.size());
  const double mean = sum / n;
  EXPECT_NEAR(mean, 1.0, 0.01);
  EXPECT_NEAR(std::sqrt(square / n - mean * mean), 0.2, 0.01);
}

}  // namespace
}  // namespace relight::synth
