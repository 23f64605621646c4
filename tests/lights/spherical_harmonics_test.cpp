#include "relight/lights/spherical_harmonics.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "relight/lights/probe_geometry.h"

namespace relight::lights {
namespace {

using Eigen::Vector3d;

/// Directions and weights of a lat-long quadrature over the sphere.
template <typename F>
void integrate_sphere(int width, F&& body) {
  const ProbeGeometry geometry(ProbeCalibration::equirectangular(), width, width / 2);
  for (int row = 0; row < width / 2; ++row) {
    for (int col = 0; col < width; ++col) body(*geometry.direction(col, row), geometry.solid_angle(row, col));
  }
}

TEST(SphericalHarmonics, TheBasisIsOrthonormal) {
  Eigen::Matrix<double, 9, 9> gram = Eigen::Matrix<double, 9, 9>::Zero();
  integrate_sphere(512, [&](const Vector3d& d, double weight) {
    const auto y = sh_basis(d);
    for (int i = 0; i < 9; ++i) {
      for (int j = 0; j < 9; ++j)
        gram(i, j) += weight * y[static_cast<std::size_t>(i)] * y[static_cast<std::size_t>(j)];
    }
  });
  EXPECT_LT((gram - Eigen::Matrix<double, 9, 9>::Identity()).cwiseAbs().maxCoeff(), 2e-3);
}

TEST(SphericalHarmonics, ADirectionalLightsIrradianceIsTheClampedCosineWithinTheOrder2Error) {
  const Vector3d d = Vector3d(0.4, -0.3, 0.85).normalized();
  const Vector3d power{2.0, 1.5, 1.0};
  const ShRgb irradiance = sh_of_directional_light(d, power).radiance_to_irradiance();
  double worst = 0.0;
  integrate_sphere(64, [&](const Vector3d& n, double) {
    const Vector3d exact = power * std::max(0.0, n.dot(d));
    worst = std::max(worst, (irradiance.evaluate(n) - exact).cwiseQuotient(power).cwiseAbs().maxCoeff());
  });
  // Ramamoorthi & Hanrahan: order 2 keeps ~99 % of max(0, cos); pointwise it errs by < 0.1.
  EXPECT_LT(worst, 0.1);
  EXPECT_GT(worst, 0.01);  // it is an approximation: the clamped cosine has higher bands
}

TEST(SphericalHarmonics, AConstantEnvironmentGivesPiTimesItsRadianceAndNoDominantLight) {
  ShRgb radiance;
  radiance.coefficients[0] = Vector3d::Constant(0.3 / sh_basis(Vector3d::UnitZ())[0]);
  const ShRgb irradiance = radiance.radiance_to_irradiance();
  EXPECT_NEAR(irradiance.evaluate(Vector3d::UnitX()).x(), 0.3 * std::numbers::pi, 1e-6);
  EXPECT_NEAR(irradiance.evaluate(-Vector3d::UnitZ()).y(), 0.3 * std::numbers::pi, 1e-6);
  EXPECT_EQ(sh_directional_power(radiance, Vector3d::UnitZ()), Vector3d::Zero());
  const RadianceImage map = sh_to_latlong(radiance, 32, 16);
  for (const Float3& p : map.pixels()) EXPECT_NEAR(p.x, 0.3f, 1e-5f);
}

TEST(SphericalHarmonics, OneLightsDirectionAndPowerAreRecoveredFromBand1) {
  const Vector3d d = Vector3d(-0.5, 0.2, 0.7).normalized();
  ShRgb radiance = sh_of_directional_light(d, {3.0, 2.0, 1.0});
  radiance.coefficients[0] += Vector3d::Constant(0.5);  // an ambient that has no direction
  EXPECT_LT(std::acos(std::min(1.0, sh_dominant_direction(radiance).dot(d))), 1e-6);
  EXPECT_LT((sh_directional_power(radiance, d) - Vector3d(3.0, 2.0, 1.0)).norm(), 1e-4);
  // The lat-long map integrates to the same irradiance as the coefficients (clamping aside).
  const ShRgb ambient = [] {
    ShRgb a;
    a.coefficients[0] = Vector3d::Constant(1.0);
    a.coefficients[2] = Vector3d::Constant(0.5);
    return a;
  }();
  const RadianceImage map = sh_to_latlong(ambient, 256, 128);
  const ProbeGeometry geometry(ProbeCalibration::equirectangular(), 256, 128);
  double up = 0.0;
  for (int row = 0; row < 128; ++row) {
    for (int col = 0; col < 256; ++col) {
      up += map(row, col).x * geometry.solid_angle(row, col) * std::max(0.0, geometry.direction(col, row)->z());
    }
  }
  EXPECT_NEAR(up, ambient.radiance_to_irradiance().evaluate(Vector3d::UnitZ()).x(), 0.01 * up);
}

}  // namespace
}  // namespace relight::lights
