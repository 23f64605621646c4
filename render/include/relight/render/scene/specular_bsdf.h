#pragma once
// Sampling the perfectly specular materials of specular_material.h for the path tracer's camera
// paths and its caustic light paths (reference/path_tracer.h). Both scattering directions are
// deltas, so a sample is the direction and its weight f cos / pdf, with the choice between
// reflection and refraction made in proportion to the Fresnel term (Veach's thesis §5.2 and
// PBRT's "specular reflection and transmission"):
//
//   conductor:  wi = r(wo) = 2 (n.wo) n - wo,               weight F_schlick(n.wo)
//   dielectric: wi = r(wo) with probability F,              weight 1
//               wi = t(wo) (Snell) with probability 1 - F,  weight (eta_o / eta_i)^2 for radiance,
//                                                            1 for importance (light paths)
//
// where F is the exact unpolarised Fresnel reflectance and eta_o, eta_i the indices on wo's and
// wi's side: radiance is compressed by eta^2 entering a denser medium (the non-symmetric
// scattering at refractive interfaces, Veach §5.2), while the flux a light path carries is not.
// For a closed object the two factors of its entry and exit cancel.
//
// All vectors are unit and point away from the surface; `outward` is the triangle's normal as its
// winding gives it (out of a closed dielectric), so n.wo > 0 means wo is outside.
#include <Eigen/Core>
#include <optional>

#include "relight/render/scene/specular_material.h"

namespace relight::render {

/// Fresnel reflectance of unpolarised light arriving at cosine `cos_i` (>= 0) from a medium of
/// index eta_i onto one of eta_t; 1 beyond the critical angle (total internal reflection).
[[nodiscard]] float dielectric_fresnel(float cos_i, float eta_i, float eta_t);

/// Schlick's approximation F0 + (1 - F0) (1 - cos)^5, per channel.
[[nodiscard]] Eigen::Vector3f schlick_fresnel(const Eigen::Vector3f& f0, float cos_i);

/// The refraction of `wo` (unit, on the side `normal` points to) into the other side by Snell's
/// law with eta = eta_o / eta_i (wo's index over the other's); nullopt at total internal
/// reflection.
[[nodiscard]] std::optional<Eigen::Vector3f> refract(const Eigen::Vector3f& wo, const Eigen::Vector3f& normal,
                                                     float eta);

/// Beer-Lambert: the share of light left per channel after `distance` metres inside `material`.
[[nodiscard]] Eigen::Vector3f beer_lambert(const SpecularMaterial& material, float distance);

/// What a sample carries: radiance (camera paths) or importance (light paths, flux).
enum class Transport { Radiance, Importance };

struct SpecularSample {
  Eigen::Vector3f wi;
  Eigen::Vector3f weight;    ///< f cos / pdf of the chosen delta
  bool transmitted = false;  ///< wi crossed the surface (refraction)
};

/// Both deltas at once, for renderers that follow every branch instead of choosing one (DIR's
/// secondary G-buffers, dir/specular_gbuffer.h): the reflection with weight F (conductor: the
/// Schlick colour; dielectric: the exact F) and, for a dielectric short of total internal
/// reflection, the refraction with weight (1 - F) times the transport's eta factor. Empty for a
/// non-specular material.
struct SpecularLobes {
  std::optional<SpecularSample> reflected, refracted;
};
[[nodiscard]] SpecularLobes specular_lobes(const SpecularMaterial& material, const Eigen::Vector3f& outward,
                                           const Eigen::Vector3f& wo, Transport transport);

/// Samples the specular direction at a surface of `material` with the winding's normal `outward`
/// seen from wo, using one uniform number `u` for the reflection/refraction choice. nullopt for a
/// non-specular material.
[[nodiscard]] std::optional<SpecularSample> sample_specular(const SpecularMaterial& material,
                                                            const Eigen::Vector3f& outward, const Eigen::Vector3f& wo,
                                                            float u, Transport transport);

}  // namespace relight::render
