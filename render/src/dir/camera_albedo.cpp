// Per-pixel albedo modulation of the real surfaces (camera_albedo.h).
#include "relight/render/dir/camera_albedo.h"

#include <algorithm>

#include "relight/brdf/diffuse.h"
#include "relight/core/error.h"
#include "relight/core/parallel.h"

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

/// Per pixel, whether it takes part: a real surface of a diffuse material with a valid estimate.
Mask modulated_pixels(const GBuffer& gbuffer, const MrScene& scene, const Mask& valid) {
  Mask out(valid.width(), valid.height());
  for (std::size_t i = 0; i < out.size(); ++i) {
    const std::uint16_t label = gbuffer.material.pixels()[i];
    out.pixels()[i] = label != 0 && !gbuffer.virtual_surface.pixels()[i] && brdf::has_kd(valid.pixels()[i]) &&
                              scene.materials.at(label - 1u).ks == 0.f
                          ? 1
                          : 0;
  }
  return out;
}

/// k_d averaged over the (2 kAlbedoSmoothingRadius + 1)² window's modulated pixels of the same
/// material; zero where the pixel itself is not modulated.
RadianceImage smoothed_albedo(const GBuffer& gbuffer, const RadianceImage& albedo, const Mask& modulated) {
  const int width = albedo.width(), height = albedo.height();
  RadianceImage out(width, height);
  parallel_rows(height, 0, [&](int begin, int end) {
    for (int y = begin; y < end; ++y)
      for (int x = 0; x < width; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x);
        if (!modulated.pixels()[i]) continue;
        const std::uint16_t label = gbuffer.material.pixels()[i];
        Float3 sum{};
        int count = 0;
        for (int v = std::max(0, y - kAlbedoSmoothingRadius); v <= std::min(height - 1, y + kAlbedoSmoothingRadius); ++v)
          for (int u = std::max(0, x - kAlbedoSmoothingRadius); u <= std::min(width - 1, x + kAlbedoSmoothingRadius); ++u) {
            const std::size_t j = static_cast<std::size_t>(v) * static_cast<std::size_t>(width) + static_cast<std::size_t>(u);
            if (gbuffer.material.pixels()[j] != label || !modulated.pixels()[j]) continue;
            sum = sum + albedo.pixels()[j];
            ++count;
          }
        out.pixels()[i] = (1.f / static_cast<float>(count)) * sum;
      }
  });
  return out;
}

}  // namespace

void modulate_camera_albedo(DifferentialImages& images, const GBuffer& gbuffer, const MrScene& scene,
                            const RadianceImage& albedo, const Mask& valid) {
  if (!images.real.same_shape(gbuffer.material) || !albedo.same_shape(gbuffer.material) ||
      !valid.same_shape(gbuffer.material) || !images.real_virtual.same_shape(images.real))
    throw Error("camera albedo: the G-buffer, the rendered images and the albedo image differ in size");
  const bool has_indirect = images.indirect_real.same_shape(images.real) && images.indirect_real_virtual.same_shape(images.real);
  const Mask modulated = modulated_pixels(gbuffer, scene, valid);
  const RadianceImage smoothed = smoothed_albedo(gbuffer, albedo, modulated);
  for (std::size_t i = 0; i < images.real.size(); ++i) {
    if (!modulated.pixels()[i]) continue;
    const PhongMaterial& material = scene.materials.at(gbuffer.material.pixels()[i] - 1u);
    const Float3 factor = albedo_ratio(smoothed.pixels()[i], material.kd);
    images.real.pixels()[i] = scaled(images.real.pixels()[i], factor);
    images.real_virtual.pixels()[i] = scaled(images.real_virtual.pixels()[i], factor);
    if (!has_indirect) continue;
    images.indirect_real.pixels()[i] = scaled(images.indirect_real.pixels()[i], factor);
    images.indirect_real_virtual.pixels()[i] = scaled(images.indirect_real_virtual.pixels()[i], factor);
  }
}

}  // namespace relight::render
