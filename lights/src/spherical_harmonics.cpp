#include "relight/lights/spherical_harmonics.h"

#include <numbers>

#include "relight/lights/light_set.h"
#include "relight/lights/probe_geometry.h"

namespace relight::lights {

std::array<double, kShCoefficients> sh_basis(const Eigen::Vector3d& d) {
  const double x = d.x();
  const double y = d.y();
  const double z = d.z();
  return {0.282095,
          0.488603 * y,
          0.488603 * z,
          0.488603 * x,
          1.092548 * x * y,
          1.092548 * y * z,
          0.315392 * (3.0 * z * z - 1.0),
          1.092548 * x * z,
          0.546274 * (x * x - y * y)};
}

double sh_cosine_factor(int i) {
  constexpr std::array<double, 3> kBand{std::numbers::pi, 2.0 * std::numbers::pi / 3.0, std::numbers::pi / 4.0};
  return kBand[static_cast<std::size_t>(sh_band(i))];
}

Eigen::Vector3d ShRgb::evaluate(const Eigen::Vector3d& d) const {
  const auto basis = sh_basis(d);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < basis.size(); ++i) sum += basis[i] * coefficients[i];
  return sum;
}

ShRgb ShRgb::radiance_to_irradiance() const {
  ShRgb out = *this;
  for (int i = 0; i < kShCoefficients; ++i) out.coefficients[static_cast<std::size_t>(i)] *= sh_cosine_factor(i);
  return out;
}

ShRgb ShRgb::irradiance_to_radiance() const {
  ShRgb out = *this;
  for (int i = 0; i < kShCoefficients; ++i) out.coefficients[static_cast<std::size_t>(i)] /= sh_cosine_factor(i);
  return out;
}

ShRgb& ShRgb::operator-=(const ShRgb& other) {
  for (std::size_t i = 0; i < coefficients.size(); ++i) coefficients[i] -= other.coefficients[i];
  return *this;
}

ShRgb ShRgb::operator*(double factor) const {
  ShRgb out = *this;
  for (auto& c : out.coefficients) c *= factor;
  return out;
}

ShRgb sh_of_directional_light(const Eigen::Vector3d& d, const Eigen::Vector3d& power) {
  ShRgb out;
  const auto basis = sh_basis(d.normalized());
  for (std::size_t i = 0; i < basis.size(); ++i) out.coefficients[i] = basis[i] * power;
  return out;
}

Eigen::Vector3d sh_dominant_direction(const ShRgb& radiance) {
  // Band 1 is (Y1-1, Y10, Y11) = c (y, z, x): the luminance-weighted mean direction.
  const auto lum = [&](std::size_t i) { return luminance(radiance.coefficients[i]); };
  const Eigen::Vector3d d{lum(3), lum(1), lum(2)};
  return d.norm() > 0.0 ? Eigen::Vector3d(d.normalized()) : Eigen::Vector3d::UnitZ();
}

Eigen::Vector3d sh_directional_power(const ShRgb& radiance, const Eigen::Vector3d& d) {
  // A delta of power P along d has band-1 coefficients 0.488603 P (d.y, d.z, d.x).
  const Eigen::Vector3d unit = d.normalized();
  const Eigen::Vector3d along =
      unit.x() * radiance.coefficients[3] + unit.y() * radiance.coefficients[1] + unit.z() * radiance.coefficients[2];
  return (along / 0.488603).cwiseMax(0.0);
}

RadianceImage sh_to_latlong(const ShRgb& radiance, int width, int height) {
  const ProbeGeometry geometry(ProbeCalibration::equirectangular(), width, height);
  RadianceImage out(width, height);
  for (int row = 0; row < height; ++row) {
    for (int col = 0; col < width; ++col) {
      const Eigen::Vector3d value = radiance.evaluate(*geometry.direction(col, row)).cwiseMax(0.0);
      out(row, col) = {static_cast<float>(value.x()), static_cast<float>(value.y()), static_cast<float>(value.z())};
    }
  }
  return out;
}

}  // namespace relight::lights
