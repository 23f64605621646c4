#pragma once
// Order-2 real spherical harmonics (bands 0..2, nine coefficients per colour channel): the
// irradiance environment of Ramamoorthi & Hanrahan ("An Efficient Representation for Irradiance
// Environment Maps", SIGGRAPH 2001). Diffuse shading only sees a distant environment through
// these nine numbers (the clamped cosine's higher bands carry < 1 % of its energy), which is why
// light estimation fits them (brdf/light_estimation.h) and why a sharp light's direction needs
// other evidence (cast shadows).
//
// Basis order: Y00, Y1-1, Y10, Y11, Y2-2, Y2-1, Y20, Y21, Y22 with, for a unit (x, y, z),
//   Y00 = 0.282095;  Y1-1 = 0.488603 y;  Y10 = 0.488603 z;  Y11 = 0.488603 x;
//   Y2-2 = 1.092548 xy;  Y2-1 = 1.092548 yz;  Y21 = 1.092548 xz;
//   Y20 = 0.315392 (3 z^2 - 1);  Y22 = 0.546274 (x^2 - y^2).
// Irradiance and radiance coefficients differ by the clamped cosine's band factors (their eq. 8):
//   E_lm = A_l L_lm,  A_0 = pi, A_1 = 2 pi / 3, A_2 = pi / 4.
// Directions are in whatever frame the caller keeps (the world frame in the product).
#include <Eigen/Core>
#include <array>

#include "relight/core/image.h"

namespace relight::lights {

inline constexpr int kShCoefficients = 9;

/// The nine basis functions at unit direction `d`.
[[nodiscard]] std::array<double, kShCoefficients> sh_basis(const Eigen::Vector3d& d);

/// Band l (0, 1 or 2) of coefficient index i.
[[nodiscard]] constexpr int sh_band(int i) { return i == 0 ? 0 : (i < 4 ? 1 : 2); }

/// A_l of the coefficient index i (the clamped cosine's convolution factor).
[[nodiscard]] double sh_cosine_factor(int i);

/// An RGB function on the sphere in the basis above.
struct ShRgb {
  ShRgb() { coefficients.fill(Eigen::Vector3d::Zero()); }  // Eigen does not zero its vectors
  std::array<Eigen::Vector3d, kShCoefficients> coefficients;

  [[nodiscard]] Eigen::Vector3d evaluate(const Eigen::Vector3d& d) const;
  /// Irradiance coefficients of this radiance (A_l L_lm), or radiance of this irradiance.
  [[nodiscard]] ShRgb radiance_to_irradiance() const;
  [[nodiscard]] ShRgb irradiance_to_radiance() const;
  ShRgb& operator-=(const ShRgb& other);
  [[nodiscard]] ShRgb operator*(double factor) const;
};

/// Radiance coefficients of a distant light from unit direction `d` delivering irradiance `power`
/// to a surface facing it (a delta: L_lm = power Y_lm(d)).
[[nodiscard]] ShRgb sh_of_directional_light(const Eigen::Vector3d& d, const Eigen::Vector3d& power);

/// The direction the band-1 coefficients of luminance point to (the "optimal linear direction"
/// of Sloan's "Stupid SH tricks"): unit, or +z when band 1 is zero.
[[nodiscard]] Eigen::Vector3d sh_dominant_direction(const ShRgb& radiance);

/// The power of the directional light along unit `d` whose band-1 coefficients match those of
/// `radiance` projected on d (per channel, floored at 0): exact for one directional light, zero
/// for an environment without a preferred direction (band 0 and 2 alone cast no shadow).
[[nodiscard]] Eigen::Vector3d sh_directional_power(const ShRgb& radiance, const Eigen::Vector3d& d);

/// `radiance` evaluated on a width x height lat-long map in probe_geometry.h's convention (row 0
/// looks along +z, column u at azimuth 2 pi (u + 0.5) / width), negative lobes clamped to 0.
[[nodiscard]] RadianceImage sh_to_latlong(const ShRgb& radiance, int width, int height);

}  // namespace relight::lights
