#pragma once
// The normalised Phong model: relight's one reflectance model, shared by the synthetic scene that
// makes ground truth (synth/), BRDF estimation that fits it to the camera image (brdf/, the
// dissertation's eq. 4.15) and every renderer (render/: the path tracer, DIR, VPL emission):
//
//   f(wi, wo) = k_d / pi + k_s (n + 2) / (2 pi) max(0, r(wi) . wo)^n,   r(wi) = 2 (n.wi) n - wi
//
// (Lafortune & Willems 1994; the (n + 2) / (2 pi) factor keeps the lobe's energy at most k_s for
// every exponent, which is what makes an estimated k_s comparable across clusters). All vectors
// are unit and point away from the surface.
//
// The templates serve float (renderers, the fit's vectorised forms), double (the ground truth) and
// Ceres Jets (the fit's automatic derivatives). The GLSL twin is core/shaders/phong.glsl, which the
// DIR shading pass and the specular-fit objective include; tests/core/vk checks the two agree.
#include <Eigen/Core>
#include <cmath>
#include <numbers>
#include <type_traits>

namespace relight {

/// Phong parameters: diffuse albedo k_d (linear RGB), scalar specular k_s (white highlights),
/// exponent n. The material structs of the synthetic scene, the renderer and BRDF estimation all
/// derive from this one.
template <class Scalar>
struct BasicPhong {
  Eigen::Matrix<Scalar, 3, 1> kd = Eigen::Matrix<Scalar, 3, 1>::Constant(Scalar(0.5));
  Scalar ks = Scalar(0);
  Scalar n = Scalar(1);

  template <class Other>
  [[nodiscard]] BasicPhong<Other> cast() const {
    return {kd.template cast<Other>(), static_cast<Other>(ks), static_cast<Other>(n)};
  }
};
using Phong = BasicPhong<float>;

/// r(wi) . wo at or below this counts as no lobe: pow's derivative in n is pow * log(r . wo),
/// which must stay finite for the fit's Jets, and a lobe this far out is below float rounding.
inline constexpr double kPhongMinLobeCosine = 1e-12;

/// (n + 2) / (2 pi): the specular lobe's normalisation.
template <class T>
[[nodiscard]] T phong_lobe_normalisation(const T& n) {
  return (n + T(2.0)) * T(0.5 * std::numbers::inv_pi);
}

/// max(0, cos_alpha)^n with cos_alpha = r(wi) . wo (zero at or below kPhongMinLobeCosine).
template <class T>
[[nodiscard]] T phong_lobe(const T& n, const T& cos_alpha) {
  using std::pow;
  return cos_alpha > T(kPhongMinLobeCosine) ? T(pow(cos_alpha, n)) : T(0.0);
}

/// The specular term k_s (n + 2) / (2 pi) max(0, cos_alpha)^n (grey: the same in every channel).
template <class T>
[[nodiscard]] T phong_specular(const T& ks, const T& n, const T& cos_alpha) {
  return ks * phong_lobe_normalisation(n) * phong_lobe(n, cos_alpha);
}

/// The mirror direction of `direction` about unit `normal`: r = 2 (n.d) n - d.
template <class Direction, class Normal>
[[nodiscard]] Eigen::Matrix<typename Direction::Scalar, 3, 1> phong_reflect(
    const Eigen::MatrixBase<Direction>& direction, const Eigen::MatrixBase<Normal>& normal) {
  using T = typename Direction::Scalar;
  return T(2.0) * normal.dot(direction) * normal - direction;
}

/// f(wi, wo) for a surface of unit normal `normal`; zero when either direction is below it. The
/// scalar comes from the material, so the vectors may be expressions (-wi).
template <class T>
[[nodiscard]] Eigen::Matrix<T, 3, 1> phong_brdf(const BasicPhong<T>& material,
                                                const std::type_identity_t<Eigen::Matrix<T, 3, 1>>& normal,
                                                const std::type_identity_t<Eigen::Matrix<T, 3, 1>>& wi,
                                                const std::type_identity_t<Eigen::Matrix<T, 3, 1>>& wo) {
  using Vector = Eigen::Matrix<T, 3, 1>;
  if (normal.dot(wi) <= T(0) || normal.dot(wo) <= T(0)) return Vector::Zero();
  const T specular =
      material.ks > T(0) ? phong_specular(material.ks, material.n, phong_reflect(wi, normal).dot(wo)) : T(0);
  return material.kd * T(std::numbers::inv_pi) + Vector::Constant(specular);
}

}  // namespace relight
