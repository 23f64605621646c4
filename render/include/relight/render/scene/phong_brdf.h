#pragma once
// Importance sampling of relight's Phong model (core/phong.h, which evaluates f; Lafortune &
// Willems 1994) for the path tracer and the VPL tracer:
//
//   f(wi, wo) = k_d / pi + k_s (n + 2) / (2 pi) max(0, r(wi) . wo)^n,   r(wi) = 2 (n.wi) n - wi
//
// the same model as the synthetic scene and BRDF estimation, so that a material estimated there
// renders back to the camera image. Sampling picks the diffuse lobe (cosine-weighted) with
// probability p_d = lum(k_d) / (lum(k_d) + k_s) and otherwise the specular lobe (pdf
// (n + 1) / (2 pi) cos^n around r(wo)); the returned pdf is the mixture's, so the estimator
// f cos / pdf is unbiased for either choice. All vectors are unit and point away from the surface.
#include <Eigen/Core>
#include <optional>

#include "relight/render/scene/mr_scene.h"

namespace relight::render {

struct BrdfSample {
  Eigen::Vector3f wi;
  /// f(wi, wo) cos(theta_i) / pdf(wi)
  Eigen::Vector3f weight;
  float pdf = 0.f;
};

/// Samples wi given wo from two uniform numbers u1 (lobe choice and first coordinate) and u2.
/// nullopt when the material reflects nothing or the sample falls below the surface.
[[nodiscard]] std::optional<BrdfSample> sample_phong(const Phong& material, const Eigen::Vector3f& normal,
                                                     const Eigen::Vector3f& wo, float u1, float u2);

/// The mixture pdf of sample_phong for a given wi (solid-angle measure).
[[nodiscard]] float phong_pdf(const Phong& material, const Eigen::Vector3f& normal, const Eigen::Vector3f& wi,
                              const Eigen::Vector3f& wo);

/// An orthonormal basis (t, b, n) around unit n (Duff et al. 2017, no branch on a threshold).
void orthonormal_basis(const Eigen::Vector3f& n, Eigen::Vector3f& t, Eigen::Vector3f& b);

}  // namespace relight::render
