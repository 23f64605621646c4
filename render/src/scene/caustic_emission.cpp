#include "scene/caustic_emission.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "relight/render/scene/phong_brdf.h"
#include "scene/surface_shading.h"

namespace relight::render::detail {
namespace {
constexpr float kPi = std::numbers::pi_v<float>;
}  // namespace

ConeSample sample_cone_towards(const Vec3& origin, const BoundingSphere& target, float u1, float u2) {
  const float phi = 2.f * kPi * u2;
  const Vec3 to_target = target.centre - origin;
  const float distance = to_target.norm();
  if (distance <= target.radius) {
    const float z = 1.f - 2.f * u1;
    const float r = std::sqrt(std::max(0.f, 1.f - z * z));
    return {Vec3(r * std::cos(phi), r * std::sin(phi), z), 1.f / (4.f * kPi)};
  }
  const float sin2_max = (target.radius / distance) * (target.radius / distance);
  const float cos_max = std::sqrt(std::max(0.f, 1.f - sin2_max));
  const float one_minus_cos_max = sin2_max / (1.f + cos_max);  // without cancellation
  const float one_minus_cos = u1 * one_minus_cos_max;
  const float cos_theta = 1.f - one_minus_cos;
  const float sin_theta = std::sqrt(std::max(0.f, one_minus_cos * (2.f - one_minus_cos)));
  const Vec3 axis = to_target / distance;
  Vec3 t, b;
  orthonormal_basis(axis, t, b);
  return {(cos_theta * axis + sin_theta * (std::cos(phi) * t + std::sin(phi) * b)).normalized(),
          1.f / (2.f * kPi * one_minus_cos_max)};
}

std::optional<Emission> emit_towards(const MrLight& light, const BoundingSphere& target, const BoundingSphere& scene,
                                     float u1, float u2) {
  if (light.kind == LightKind::Directional) {
    const float phi = 2.f * kPi * u2;
    const Vec3 to_light = light.direction.normalized();
    Vec3 t, b;
    orthonormal_basis(to_light, t, b);
    const float r = target.radius * std::sqrt(u1);
    const Vec3 on_disc = target.centre + r * (std::cos(phi) * t + std::sin(phi) * b);
    const float far = (scene.centre - target.centre).norm() + scene.radius + target.radius + 1.f;
    return Emission{on_disc + far * to_light, -to_light, light.intensity * (kPi * target.radius * target.radius)};
  }
  const auto [direction, pdf] = sample_cone_towards(light.position, target, u1, u2);
  const float falloff = light.kind == LightKind::Spot ? spot_falloff(light, direction) : 1.f;
  if (!(falloff > 0.f) || !(pdf > 0.f) || !std::isfinite(pdf)) return std::nullopt;
  return Emission{light.position, direction, light.intensity * (falloff / pdf)};
}

}  // namespace relight::render::detail
