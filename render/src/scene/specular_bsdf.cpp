#include "relight/render/scene/specular_bsdf.h"

#include <algorithm>
#include <cmath>

namespace relight::render {

float dielectric_fresnel(float cos_i, float eta_i, float eta_t) {
  cos_i = std::clamp(cos_i, 0.f, 1.f);
  const float sin_t = eta_i / eta_t * std::sqrt(std::max(0.f, 1.f - cos_i * cos_i));
  if (sin_t >= 1.f) return 1.f;
  const float cos_t = std::sqrt(std::max(0.f, 1.f - sin_t * sin_t));
  const float parallel = (eta_t * cos_i - eta_i * cos_t) / (eta_t * cos_i + eta_i * cos_t);
  const float perpendicular = (eta_i * cos_i - eta_t * cos_t) / (eta_i * cos_i + eta_t * cos_t);
  return 0.5f * (parallel * parallel + perpendicular * perpendicular);
}

Eigen::Vector3f schlick_fresnel(const Eigen::Vector3f& f0, float cos_i) {
  const float m = 1.f - std::clamp(cos_i, 0.f, 1.f);
  const float m2 = m * m;
  return f0 + (Eigen::Vector3f::Ones() - f0) * (m2 * m2 * m);
}

std::optional<Eigen::Vector3f> refract(const Eigen::Vector3f& wo, const Eigen::Vector3f& normal, float eta) {
  const float cos_o = normal.dot(wo);
  const float sin2_t = eta * eta * std::max(0.f, 1.f - cos_o * cos_o);
  if (sin2_t >= 1.f) return std::nullopt;
  const float cos_t = std::sqrt(1.f - sin2_t);
  return Eigen::Vector3f(-eta * wo + (eta * cos_o - cos_t) * normal).normalized();
}

Eigen::Vector3f beer_lambert(const SpecularMaterial& material, float distance) {
  if (!std::isfinite(material.attenuation_distance) || distance <= 0.f) return Eigen::Vector3f::Ones();
  const float exponent = distance / material.attenuation_distance;
  return material.attenuation_color.unaryExpr([exponent](float c) { return std::pow(c, exponent); });
}

SpecularLobes specular_lobes(const SpecularMaterial& material, const Eigen::Vector3f& outward,
                             const Eigen::Vector3f& wo, Transport transport) {
  const bool outside = outward.dot(wo) >= 0.f;
  const Eigen::Vector3f normal = outside ? outward : Eigen::Vector3f(-outward);  // on wo's side
  const float cos_o = normal.dot(wo);
  const Eigen::Vector3f mirrored = 2.f * cos_o * normal - wo;
  SpecularLobes lobes;
  switch (material.kind) {
    case SpecularKind::None: break;
    case SpecularKind::Conductor:
      lobes.reflected = SpecularSample{mirrored, schlick_fresnel(material.reflectance, cos_o), false};
      break;
    case SpecularKind::Dielectric: {
      const float eta_o = outside ? 1.f : material.ior;
      const float eta_i = outside ? material.ior : 1.f;
      const std::optional<Eigen::Vector3f> transmitted = refract(wo, normal, eta_o / eta_i);
      // F is 1 at total internal reflection, up to rounding where refract() already refuses.
      const float fresnel = transmitted ? dielectric_fresnel(cos_o, eta_o, eta_i) : 1.f;
      lobes.reflected = SpecularSample{mirrored, Eigen::Vector3f::Constant(fresnel), false};
      if (transmitted && fresnel < 1.f) {
        const float scale = transport == Transport::Radiance ? (eta_o / eta_i) * (eta_o / eta_i) : 1.f;
        lobes.refracted = SpecularSample{*transmitted, Eigen::Vector3f::Constant((1.f - fresnel) * scale), true};
      }
      break;
    }
  }
  return lobes;
}

std::optional<SpecularSample> sample_specular(const SpecularMaterial& material, const Eigen::Vector3f& outward,
                                              const Eigen::Vector3f& wo, float u, Transport transport) {
  SpecularLobes lobes = specular_lobes(material, outward, wo, transport);
  if (!lobes.reflected) return std::nullopt;
  if (material.kind == SpecularKind::Conductor) return lobes.reflected;
  // The dielectric's choice in proportion to F: each lobe's weight over its probability.
  const float fresnel = lobes.reflected->weight.x();
  if (!lobes.refracted || u < fresnel) return SpecularSample{lobes.reflected->wi, Eigen::Vector3f::Ones(), false};
  lobes.refracted->weight /= 1.f - fresnel;
  return lobes.refracted;
}

}  // namespace relight::render
