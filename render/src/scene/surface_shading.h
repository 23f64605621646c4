#pragma once
// Shading helpers shared by the CPU renderers (reference/path_tracer.cpp, reference/dir_exact.cpp, vpl/vpl.cpp): a hit
// prepared for shading, ray offsets, and next-event estimation of the primary lights.
#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <optional>

#include "relight/render/scene/mr_scene.h"
#include "relight/render/scene/phong_brdf.h"
#include "relight/render/reference/ray_tracer.h"

namespace relight::render::detail {

using Vec3 = Eigen::Vector3f;

/// A surface point prepared for shading: both normals on the side the ray came from.
struct Vertex {
  Vec3 point;
  Vec3 geometric_normal;
  Vec3 shading_normal;
  Vec3 wo;
  Phong brdf;     ///< the material's, textured at the point
  Vec3 emission;  ///< the material's, textured at the point
  /// The material's specular part (specular_material.h), null when it is not specular; then
  /// `outward` is the interpolated normal on the side the triangle's winding points to (out of a
  /// closed object), whichever side the ray came from.
  const SpecularMaterial* specular = nullptr;
  Vec3 outward = Vec3::Zero();
};

inline Vertex make_vertex(const SurfaceHit& hit, const Vec3& direction, const MrScene& scene) {
  Vertex v;
  v.point = hit.point;
  v.wo = -direction;
  v.geometric_normal = hit.geometric_normal.dot(v.wo) < 0.f ? Vec3(-hit.geometric_normal) : hit.geometric_normal;
  v.shading_normal = hit.shading_normal.dot(v.geometric_normal) < 0.f ? Vec3(-hit.shading_normal) : hit.shading_normal;
  // An interpolated normal can face away from a grazing viewer; shade with the true one there.
  if (v.shading_normal.dot(v.wo) <= 0.f) v.shading_normal = v.geometric_normal;
  v.brdf = phong_at(scene, hit);
  v.emission = emission_at(scene, hit);
  const SpecularMaterial& specular = scene.materials[hit.material].specular;
  if (specular.specular()) {
    v.specular = &specular;
    v.outward = hit.interpolated_normal.dot(hit.geometric_normal) < 0.f ? Vec3(-hit.interpolated_normal)
                                                                        : hit.interpolated_normal;
  }
  return v;
}

/// The nearest hit along a ray in the real scene (with_virtual false) or in the whole scene,
/// counting the layer queries in `rays`.
inline std::optional<SurfaceHit> nearest_hit(const RayTracer& tracer, const Vec3& origin, const Vec3& direction,
                                             bool with_virtual, std::uint32_t& rays) {
  ++rays;
  std::optional<SurfaceHit> hit = tracer.intersect(Layer::Real, origin, direction);
  if (!with_virtual || !tracer.has_virtual_geometry()) return hit;
  ++rays;
  std::optional<SurfaceHit> virtual_hit =
      tracer.intersect(Layer::Virtual, origin, direction, hit ? hit->t : std::numeric_limits<float>::infinity());
  return virtual_hit ? virtual_hit : hit;
}

/// Ray origin just off the surface on the side `direction` leaves towards (avoids self-hits).
inline Vec3 offset_origin(const Vertex& v, const Vec3& direction) {
  const float scale = 1e-4f * (1.f + v.point.cwiseAbs().maxCoeff());
  const float side = direction.dot(v.geometric_normal) >= 0.f ? 1.f : -1.f;
  return v.point + side * scale * v.geometric_normal;
}

struct LightSample {
  Vec3 wi;
  float distance = 0.f;  ///< infinity for directional lights
  Vec3 irradiance;       ///< at normal incidence
};

inline float spot_falloff(const MrLight& light, const Vec3& from_light) {
  const float c = light.direction.normalized().dot(from_light);
  if (c <= light.cos_outer) return 0.f;
  if (c >= light.cos_inner) return 1.f;
  const float x = (c - light.cos_outer) / (light.cos_inner - light.cos_outer);
  return x * x * (3.f - 2.f * x);
}

inline std::optional<LightSample> sample_light(const MrLight& light, const Vec3& point) {
  if (light.kind == LightKind::Directional)
    return LightSample{light.direction.normalized(), std::numeric_limits<float>::infinity(), light.intensity};
  const Vec3 to_light = light.position - point;
  const float distance2 = to_light.squaredNorm();
  if (!(distance2 > 0.f)) return std::nullopt;
  const float distance = std::sqrt(distance2);
  const Vec3 wi = to_light / distance;
  const float falloff = light.kind == LightKind::Spot ? spot_falloff(light, -wi) : 1.f;
  if (falloff <= 0.f) return std::nullopt;
  return LightSample{wi, distance, light.intensity * (falloff / distance2)};
}

/// Next-event estimate f cos E of a light sample at v (without visibility), or zero.
inline Vec3 direct_light(const Vertex& v, const LightSample& sample) {
  if (sample.wi.dot(v.geometric_normal) <= 0.f) return Vec3::Zero();
  const float cos_i = sample.wi.dot(v.shading_normal);
  if (cos_i <= 0.f) return Vec3::Zero();
  return phong_brdf(v.brdf, v.shading_normal, sample.wi, v.wo).cwiseProduct(sample.irradiance) * cos_i;
}

}  // namespace relight::render::detail
