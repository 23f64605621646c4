// Reflective shadow maps of spot lights by ray casting (reflective_shadow_map.h).
#include "relight/render/vpl/reflective_shadow_map.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "relight/core/error.h"
#include "relight/render/scene/luminance.h"
#include "relight/render/scene/phong_brdf.h"
#include "scene/surface_shading.h"

namespace relight::render {
namespace {

using Vec3 = Eigen::Vector3f;

/// The centre of texel (x, y) on the view's image plane at distance 1 along the axis.
Eigen::Vector2f texel_centre(const RsmView& view, int x, int y) {
  return {-view.half_extent + (static_cast<float>(x) + 0.5f) * view.texel_side,
          -view.half_extent + (static_cast<float>(y) + 0.5f) * view.texel_side};
}

/// The light's emission through the texel at `centre`, in `direction`: I(omega) falloff(omega) dOmega.
Vec3 texel_emitted(const MrLight& light, const RsmView& view, const Eigen::Vector2f& centre, const Vec3& direction) {
  const float r2 = 1.f + centre.x() * centre.x() + centre.y() * centre.y();
  // dOmega = dA cos(theta) / r^2 with cos(theta) = 1 / r on the plane at distance 1.
  const float solid_angle = view.texel_side * view.texel_side / (r2 * std::sqrt(r2));
  return light.intensity * (detail::spot_falloff(light, direction) * solid_angle);
}

/// The texel's hit, flux and importance for a surface `hit` (or none).
void fill_texel(RsmTexel& texel, const MrScene& scene, const std::optional<SurfaceHit>& hit, const Vec3& emitted) {
  texel.hit = hit;
  if (!hit) return;
  texel.flux = emitted;
  const float albedo = std::max(luminance(phong_at(scene, *hit).kd), kMinAlbedo);
  texel.importance = std::max(0.f, luminance(emitted)) * albedo;
}

}  // namespace

std::vector<float> ReflectiveShadowMap::importance() const {
  std::vector<float> values(texels.size());
  for (std::size_t i = 0; i < texels.size(); ++i) values[i] = texels[i].importance;
  return values;
}

std::size_t ReflectiveShadowMap::covered() const {
  std::size_t count = 0;
  for (const RsmTexel& texel : texels) count += texel.importance > 0.f ? 1 : 0;
  return count;
}

bool has_reflective_shadow_maps(const MrLight& light) {
  constexpr float kMaxHalfAngle = kMaxRsmHalfAngleDeg * std::numbers::pi_v<float> / 180.f;
  return light.kind == LightKind::Spot && light.cos_outer >= std::cos(kMaxHalfAngle);
}

RsmView rsm_view(const MrScene& scene, std::size_t light_index, int size, const char* who) {
  if (light_index >= scene.lights.size()) throw LogicError(std::string(who) + ": no such light");
  const MrLight& light = scene.lights[light_index];
  if (!has_reflective_shadow_maps(light)) throw LogicError(std::string(who) + ": not a spot light of <= 75 degrees");
  if (size < 1 || !std::has_single_bit(static_cast<unsigned>(size)))
    throw LogicError(std::string(who) + ": size " + std::to_string(size) + " is not a power of two");
  RsmView view;
  view.axis = light.direction.normalized();
  orthonormal_basis(view.axis, view.tangent, view.bitangent);
  const float cos_outer = std::clamp(light.cos_outer, 1e-3f, 1.f);
  view.half_extent = std::sqrt(1.f - cos_outer * cos_outer) / cos_outer;
  view.texel_side = 2.f * view.half_extent / static_cast<float>(size);
  view.size = size;
  return view;
}

std::vector<ReflectiveShadowMap> assemble_reflective_shadow_maps(const MrScene& scene, std::size_t light_index,
                                                                 const RsmView& view, const RsmTexelHitsFn& hits) {
  const MrLight& light = scene.lights.at(light_index);
  const int size = view.size;
  const auto texel_count = static_cast<std::size_t>(size) * static_cast<std::size_t>(size);
  std::vector<ReflectiveShadowMap> maps(light.real ? 2 : 1, ReflectiveShadowMap{size, std::vector<RsmTexel>(texel_count)});
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const Eigen::Vector2f centre = texel_centre(view, x, y);
      const Vec3 direction = (centre.x() * view.tangent + centre.y() * view.bitangent + view.axis).normalized();
      const Vec3 emitted = texel_emitted(light, view, centre, direction);
      const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(size) + static_cast<std::size_t>(x);
      const RsmTexelHits seen = hits(x, y, direction);
      for (ReflectiveShadowMap& map : maps) map.texels[i].direction = direction;
      fill_texel(maps[0].texels[i], scene, seen.first, emitted);
      if (!light.real) continue;
      maps[0].texels[i].occluded_by_virtual = seen.virtual_in_front.has_value();
      fill_texel(maps[1].texels[i], scene, seen.virtual_in_front, emitted);
    }
  return maps;
}

std::vector<ReflectiveShadowMap> reflective_shadow_maps_cpu(const MrScene& scene, const RayTracer& tracer,
                                                            std::size_t light_index, int size) {
  const RsmView view = rsm_view(scene, light_index, size, "reflective_shadow_maps_cpu");
  const MrLight& light = scene.lights[light_index];
  return assemble_reflective_shadow_maps(scene, light_index, view, [&](int, int, const Vec3& direction) {
    std::optional<SurfaceHit> real = tracer.intersect(Layer::Real, light.position, direction);
    std::optional<SurfaceHit> virtual_hit = tracer.intersect(
        Layer::Virtual, light.position, direction, real ? real->t : std::numeric_limits<float>::infinity());
    if (light.real) return RsmTexelHits{std::move(real), std::move(virtual_hit)};
    return RsmTexelHits{virtual_hit ? std::move(virtual_hit) : std::move(real), std::nullopt};
  });
}

}  // namespace relight::render
