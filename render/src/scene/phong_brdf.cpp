#include "relight/render/scene/phong_brdf.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "relight/render/scene/luminance.h"

namespace relight::render {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;

float diffuse_probability(const Phong& m) {
  const float d = std::max(0.f, luminance(m.kd));
  const float s = std::max(0.f, m.ks);
  return d + s > 0.f ? d / (d + s) : 0.f;
}

/// Direction at angle theta (given its cosine) and azimuth phi around `axis`.
Eigen::Vector3f around(const Eigen::Vector3f& axis, float cos_theta, float phi) {
  Eigen::Vector3f t, b;
  orthonormal_basis(axis, t, b);
  const float sin_theta = std::sqrt(std::max(0.f, 1.f - cos_theta * cos_theta));
  return (sin_theta * std::cos(phi) * t + sin_theta * std::sin(phi) * b + cos_theta * axis).normalized();
}

}  // namespace

void orthonormal_basis(const Eigen::Vector3f& n, Eigen::Vector3f& t, Eigen::Vector3f& b) {
  const float sign = std::copysign(1.f, n.z());
  const float a = -1.f / (sign + n.z());
  const float c = n.x() * n.y() * a;
  t = Eigen::Vector3f(1.f + sign * n.x() * n.x() * a, sign * c, -sign * n.x());
  b = Eigen::Vector3f(c, sign + n.y() * n.y() * a, -n.y());
}

float phong_pdf(const Phong& material, const Eigen::Vector3f& normal, const Eigen::Vector3f& wi,
                const Eigen::Vector3f& wo) {
  const float cos_i = normal.dot(wi);
  if (cos_i <= 0.f) return 0.f;
  const float pd = diffuse_probability(material);
  float pdf = pd * cos_i / kPi;
  if (pd < 1.f) {
    // The specular lobe's own normalisation as a pdf: (n + 1) / (2 pi) cos^n.
    pdf += (1.f - pd) * (material.n + 1.f) / (2.f * kPi) * phong_lobe(material.n, phong_reflect(wo, normal).dot(wi));
  }
  return pdf;
}

std::optional<BrdfSample> sample_phong(const Phong& material, const Eigen::Vector3f& normal, const Eigen::Vector3f& wo,
                                       float u1, float u2) {
  if (normal.dot(wo) <= 0.f) return std::nullopt;
  const float pd = diffuse_probability(material);
  if (pd <= 0.f && material.ks <= 0.f) return std::nullopt;
  Eigen::Vector3f wi;
  if (u1 < pd) {
    const float u = u1 / pd;  // reuse the lobe choice's remaining randomness
    wi = around(normal, std::sqrt(1.f - u), 2.f * kPi * u2);
  } else {
    const float u = pd < 1.f ? (u1 - pd) / (1.f - pd) : u1;
    wi = around(phong_reflect(wo, normal), std::pow(u, 1.f / (material.n + 1.f)), 2.f * kPi * u2);
  }
  const float pdf = phong_pdf(material, normal, wi, wo);
  if (pdf <= 0.f) return std::nullopt;
  const Eigen::Vector3f weight = phong_brdf(material, normal, wi, wo) * (normal.dot(wi) / pdf);
  return BrdfSample{wi, weight, pdf};
}

}  // namespace relight::render
