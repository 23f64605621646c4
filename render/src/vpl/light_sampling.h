#pragma once
// Light sampling of VPL generation (vpl.h): directions from point and spot lights (uniform over
// the sphere or the spot's cone), the cone from a light around the virtual objects' bounding
// sphere and the disk a directional light's parallel rays start from (the virtual focus of
// VplOptions), the emitted solid angle and the luminance that the budget weighs lights by.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

#include "relight/render/scene/luminance.h"
#include "relight/render/scene/mr_scene.h"
#include "relight/render/scene/phong_brdf.h"
#include "scene/surface_shading.h"  // detail::spot_falloff

namespace relight::render::vpl_detail {

using Vec3 = Eigen::Vector3f;
inline constexpr float kPi = std::numbers::pi_v<float>;

/// Solid angle a light emits into (the spot's cone up to its outer edge).
inline float emission_solid_angle(const MrLight& light) {
  return light.kind == LightKind::Spot ? 2.f * kPi * (1.f - light.cos_outer) : 4.f * kPi;
}

inline bool emits_vpls(const MrLight&) { return true; }

struct LightSample {
  Vec3 direction;
  Vec3 intensity_over_pdf;
};

/// Uniform over the sphere (point light) or the spot's cone; u1 is stratified by the caller.
inline LightSample sample_light_direction(const MrLight& light, float u1, float u2) {
  const float phi = 2.f * kPi * u2;
  if (light.kind == LightKind::Spot) {
    const Vec3 axis = light.direction.normalized();
    const float cos_theta = 1.f - u1 * (1.f - light.cos_outer);
    const float sin_theta = std::sqrt(std::max(0.f, 1.f - cos_theta * cos_theta));
    Vec3 t, b;
    orthonormal_basis(axis, t, b);
    const Vec3 direction = (sin_theta * std::cos(phi) * t + sin_theta * std::sin(phi) * b + cos_theta * axis).normalized();
    return {direction, light.intensity * (detail::spot_falloff(light, direction) * emission_solid_angle(light))};
  }
  const float z = 1.f - 2.f * u1;
  const float r = std::sqrt(std::max(0.f, 1.f - z * z));
  return {Vec3(r * std::cos(phi), r * std::sin(phi), z), light.intensity * (4.f * kPi)};
}

/// The cone from a light position that holds the virtual objects' bounding sphere.
struct Cone {
  Vec3 axis;
  float cos_half = 1.f;
  float solid_angle = 0.f;

  [[nodiscard]] bool contains(const Vec3& direction) const { return direction.dot(axis) > cos_half; }
  [[nodiscard]] Vec3 sample(float u1, float u2) const {
    const float cos_theta = 1.f - u1 * (1.f - cos_half);
    const float sin_theta = std::sqrt(std::max(0.f, 1.f - cos_theta * cos_theta));
    Vec3 t, b;
    orthonormal_basis(axis, t, b);
    const float phi = 2.f * kPi * u2;
    return (sin_theta * std::cos(phi) * t + sin_theta * std::sin(phi) * b + cos_theta * axis).normalized();
  }
};

inline BoundingSphere virtual_bounds(const MrScene& scene) {
  Eigen::AlignedBox3f box;
  for (const TriangleMesh& mesh : scene.meshes)
    if (!mesh.real)
      for (const Vec3& p : mesh.positions) box.extend(p);
  BoundingSphere sphere;
  if (box.isEmpty()) return sphere;
  sphere.centre = box.center();
  for (const TriangleMesh& mesh : scene.meshes)
    if (!mesh.real)
      for (const Vec3& p : mesh.positions) sphere.radius = std::max(sphere.radius, (p - sphere.centre).norm());
  return sphere;
}

/// Where a directional light's parallel rays start: a disk facing the light, outside the scene.
struct Disk {
  Vec3 centre, t, b;
  float radius = 0.f;

  Disk(const Vec3& centre_, const Vec3& towards_light, float radius_) : centre(centre_), radius(radius_) {
    orthonormal_basis(towards_light, t, b);
  }
  [[nodiscard]] float area() const { return kPi * radius * radius; }
  [[nodiscard]] Vec3 sample(float u1, float u2) const {
    const float r = radius * std::sqrt(u1), phi = 2.f * kPi * u2;
    return centre + r * (std::cos(phi) * t + std::sin(phi) * b);
  }
  [[nodiscard]] bool contains(const Vec3& p) const { return (p - centre).squaredNorm() < radius * radius; }
};

inline std::optional<Cone> cone_towards(const BoundingSphere& sphere, const Vec3& from) {
  if (sphere.radius < 0.f) return std::nullopt;
  const Vec3 offset = sphere.centre - from;
  const float distance = offset.norm();
  if (distance <= 1.001f * sphere.radius) return std::nullopt;  // the light is among the virtual objects
  Cone cone;
  cone.axis = offset / distance;
  const float sin_half = sphere.radius / distance;
  cone.cos_half = std::sqrt(std::max(0.f, 1.f - sin_half * sin_half));
  cone.solid_angle = 2.f * kPi * (1.f - cone.cos_half);
  return cone;
}

}  // namespace relight::render::vpl_detail
