#include "relight/brdf/shading.h"

#include <array>
#include <cmath>
#include <numbers>

#include "relight/core/phong.h"
#include "relight/lights/merge_lights.h"

namespace relight::brdf {

ShadingLights to_camera_frame(const lights::LightSet& set, const Pose& camera_to_world,
                              const Eigen::Vector3f& ambient) {
  const Pose world_to_camera = camera_to_world.inverse();
  ShadingLights out;
  out.ambient = ambient;
  for (const lights::Light& light : set.lights) {
    if (!light.real) continue;
    ShadingLight l;
    l.point = light.kind != lights::LightKind::Directional;
    l.vector = l.point ? (world_to_camera * light.position).cast<float>()
                       : (world_to_camera.linear() * light.direction).normalized().cast<float>();
    l.power = light.power.cast<float>();
    if (light.kind == lights::LightKind::Spot) {
      l.spot = light;
      l.spot.axis = world_to_camera.linear() * light.axis;
    }
    out.lights.push_back(l);
  }
  return out;
}

ShadingLights estimation_lights(const lights::LightSet& set, const Pose& camera_to_world,
                                const Eigen::Vector3f& ambient) {
  return to_camera_frame(lights::merge_directional_lights(set, kEstimationDirectionalLights), camera_to_world, ambient);
}

LightAtPoint light_at(const ShadingLight& light, const Eigen::Vector3f& position) {
  if (!light.point) return {light.vector, light.power};
  const Eigen::Vector3f offset = light.vector - position;
  const float distance2 = offset.squaredNorm();
  const Eigen::Vector3f direction = offset / std::sqrt(distance2);
  const auto falloff = static_cast<float>(lights::spot_falloff(light.spot, -direction.cast<double>()));
  return {direction, light.power * (falloff / distance2)};
}

Eigen::Vector3f diffuse_shading(const ShadingLights& lights, const Eigen::Vector3f& position,
                                const Eigen::Vector3f& normal) {
  constexpr float inv_pi = std::numbers::inv_pi_v<float>;
  Eigen::Vector3f sum = lights.ambient;
  for (const ShadingLight& light : lights.lights) {
    const LightAtPoint at = light_at(light, position);
    const float cosine = normal.dot(at.direction);
    if (cosine > 0.f) sum += at.irradiance * (cosine * inv_pi);
  }
  return sum;
}

Eigen::Vector3f phong_radiance(const ShadingLights& lights, const Eigen::Vector3f& position,
                               const Eigen::Vector3f& normal, const Eigen::Vector3f& kd, float ks, float n) {
  constexpr float inv_pi = std::numbers::inv_pi_v<float>;
  const Eigen::Vector3f view = -position.normalized();
  Eigen::Vector3f radiance = kd.cwiseProduct(lights.ambient);
  for (const ShadingLight& light : lights.lights) {
    const LightAtPoint at = light_at(light, position);
    const float cosine = normal.dot(at.direction);
    if (cosine <= 0.f) continue;
    const float specular = phong_specular(ks, n, phong_reflect(at.direction, normal).dot(view));
    radiance += (at.irradiance * cosine).cwiseProduct(kd * inv_pi + Eigen::Vector3f::Constant(specular));
  }
  return radiance;
}

RadianceImage linearize(const ColorImage& color) {
  RadianceImage out(color.width(), color.height());
  for (std::size_t i = 0; i < color.size(); ++i) {
    const Rgb8 c = color.pixels()[i];
    out.pixels()[i] = {srgb8_to_linear(c.r), srgb8_to_linear(c.g), srgb8_to_linear(c.b)};
  }
  return out;
}

}  // namespace relight::brdf
