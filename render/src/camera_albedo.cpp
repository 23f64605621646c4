// Per-pixel albedo modulation of the real surfaces (camera_albedo.h).
#include "relight/render/camera_albedo.h"

#include "relight/core/error.h"

namespace relight::render {
namespace {

/// The per-channel factor k_d(pixel) / k_d(cluster); 1 where the cluster's channel is too dark.
Float3 albedo_ratio(const Float3& pixel, const Eigen::Vector3f& cluster) {
  const auto ratio = [](float p, float c) { return c >= kMinClusterAlbedo ? p / c : 1.f; };
  return {ratio(pixel.x, cluster.x()), ratio(pixel.y, cluster.y()), ratio(pixel.z, cluster.z())};
}

Float3 scaled(const Float3& value, const Float3& factor) {
  return {value.x * factor.x, value.y * factor.y, value.z * factor.z};
}

}  // namespace

void modulate_camera_albedo(DifferentialImages& images, const GBuffer& gbuffer, const MrScene& scene,
                            const RadianceImage& albedo, const Mask& valid) {
  if (!images.real.same_shape(gbuffer.material) || !albedo.same_shape(gbuffer.material) ||
      !valid.same_shape(gbuffer.material) || !images.real_virtual.same_shape(images.real))
    throw Error("camera albedo: the G-buffer, the rendered images and the albedo image differ in size");
  const bool has_indirect = images.indirect_real.same_shape(images.real) && images.indirect_real_virtual.same_shape(images.real);
  for (std::size_t i = 0; i < images.real.size(); ++i) {
    const std::uint16_t label = gbuffer.material.pixels()[i];
    if (label == 0 || gbuffer.virtual_surface.pixels()[i] || !valid.pixels()[i]) continue;
    const PhongMaterial& material = scene.materials.at(label - 1u);
    if (material.ks > 0.f) continue;
    const Float3 factor = albedo_ratio(albedo.pixels()[i], material.kd);
    images.real.pixels()[i] = scaled(images.real.pixels()[i], factor);
    images.real_virtual.pixels()[i] = scaled(images.real_virtual.pixels()[i], factor);
    if (!has_indirect) continue;
    images.indirect_real.pixels()[i] = scaled(images.indirect_real.pixels()[i], factor);
    images.indirect_real_virtual.pixels()[i] = scaled(images.indirect_real_virtual.pixels()[i], factor);
  }
}

}  // namespace relight::render
