// shade_dir_from_maps(): the CPU mirror of dir_shade.comp (see dir_vk.h). Keep the two in step.
#include <algorithm>

#include "relight/core/error.h"
#include "relight/core/parallel.h"
#include "relight/render/dir_vk.h"
#include "relight/render/phong_brdf.h"
#include "surface_shading.h"

namespace relight::render {
namespace {

using Vec3 = Eigen::Vector3f;

struct Radiance {
  Vec3 real_virtual = Vec3::Zero();
  Vec3 real = Vec3::Zero();
};

class MapShader {
 public:
  MapShader(const MrScene& scene, const ShadowLayout& layout, std::span<const float> shadow_atlas,
            std::span<const Vpl> vpls, std::span<const float> ism_atlas, const DirVkOptions& options)
      : scene_(scene), layout_(layout), shadow_atlas_(shadow_atlas), vpls_(vpls), ism_atlas_(ism_atlas), options_(options) {}

  [[nodiscard]] Radiance shade(const Vec3& point, const Vec3& normal, const Vec3& wo, const PhongMaterial& m,
                               float real_pixel) const {
    Radiance out;
    out.real_virtual = m.emission;
    out.real = real_pixel * m.emission;
    if (options_.shading.direct) add_direct(point, normal, wo, m, real_pixel, out);
    if (options_.shading.indirect) add_indirect(point, normal, wo, m, real_pixel, out);
    return out;
  }

 private:
  [[nodiscard]] bool want_rv() const { return options_.output != DirOutput::RealOnly; }
  [[nodiscard]] bool want_r() const { return options_.output != DirOutput::RealVirtualOnly; }

  void add_direct(const Vec3& point, const Vec3& n, const Vec3& wo, const PhongMaterial& m, float real_pixel,
                  Radiance& out) const {
    for (std::size_t l = 0; l < scene_.lights.size(); ++l) {
      const MrLight& light = scene_.lights[l];
      const std::optional<detail::LightSample> sample = detail::sample_light(light, point);
      if (!sample) continue;
      const float cos_i = sample->wi.dot(n);
      if (cos_i <= 0.f) continue;
      const Vec3 contribution = phong_brdf(m, n, sample->wi, wo).cwiseProduct(sample->irradiance) * cos_i;
      const auto index = static_cast<std::uint32_t>(l);
      if (shadow_visibility(layout_, shadow_atlas_, index, 0, point, n) == 0.f) continue;
      if (want_rv()) out.real_virtual += contribution * shadow_visibility(layout_, shadow_atlas_, index, 1, point, n);
      out.real += contribution * ((light.real ? 1.f : 0.f) * real_pixel);
    }
  }

  void add_indirect(const Vec3& point, const Vec3& n, const Vec3& wo, const PhongMaterial& m, float real_pixel,
                    Radiance& out) const {
    const float min_distance2 = options_.shading.min_distance * options_.shading.min_distance;
    const auto count = static_cast<std::uint32_t>(vpls_.size());
    for (std::uint32_t j = 0; j < count; ++j) {
      const Vpl& vpl = vpls_[j];
      const bool in_rv = want_rv() && vpl.in_real_virtual;
      const bool in_r = want_r() && vpl.in_real && real_pixel > 0.f;
      if (!in_rv && !in_r) continue;
      const Vec3 to_vpl = vpl.position - point;
      const float distance2 = to_vpl.squaredNorm();
      if (!(distance2 > 0.f)) continue;
      const Vec3 wi = to_vpl / std::sqrt(distance2);
      const float cos_x = wi.dot(n), cos_y = -wi.dot(vpl.normal);
      if (cos_x <= 0.f || cos_y <= 0.f) continue;
      const Vec3 contribution = vpl.flux.cwiseProduct(phong_brdf(scene_.materials[vpl.material], vpl.normal, vpl.incident, -wi))
                                    .cwiseProduct(phong_brdf(m, n, wi, wo)) *
                                (cos_x * cos_y / std::max(distance2, min_distance2));
      if (ism_visibility(ism_atlas_, options_.ism, count, j, 0, vpl, point) == 0.f) continue;
      if (in_rv) out.real_virtual += contribution * ism_visibility(ism_atlas_, options_.ism, count, j, 1, vpl, point);
      if (in_r) out.real += contribution;
    }
  }

  const MrScene& scene_;
  const ShadowLayout& layout_;
  std::span<const float> shadow_atlas_;
  std::span<const Vpl> vpls_;
  std::span<const float> ism_atlas_;
  const DirVkOptions& options_;
};

}  // namespace

DifferentialImages shade_dir_from_maps(const GBuffer& gbuffer, const MrScene& scene, const Vec3& camera_centre,
                                       const ShadowLayout& layout, std::span<const float> shadow_atlas,
                                       std::span<const Vpl> vpls, std::span<const float> ism_atlas,
                                       const DirVkOptions& options) {
  const int width = gbuffer.position.width(), height = gbuffer.position.height();
  if (shadow_atlas.size() < static_cast<std::size_t>(layout.atlas_width()) * static_cast<std::size_t>(layout.atlas_height()))
    throw Error("shade_dir_from_maps: the shadow atlas is smaller than its layout");
  const std::size_t ism_texels = 2 * vpls.size() * static_cast<std::size_t>(options.ism.tile) * static_cast<std::size_t>(options.ism.tile);
  if (ism_atlas.size() < ism_texels) throw Error("shade_dir_from_maps: the ISM atlas is smaller than its VPLs need");
  DifferentialImages out{RadianceImage(width, height), RadianceImage(width, height), CoverageImage(width, height), 1};
  const MapShader shader(scene, layout, shadow_atlas, vpls, ism_atlas, options);
  const Vec3 environment = scene.environment.radiance;
  parallel_rows(height, options.shading.threads, [&](int begin, int end) {
    for (int y = begin; y < end; ++y)
      for (int x = 0; x < width; ++x) {
        if (gbuffer.distance(y, x) == 0.f) {
          out.real_virtual(y, x) = out.real(y, x) = {environment.x(), environment.y(), environment.z()};
          continue;
        }
        const auto& p = gbuffer.position(y, x);
        const auto& nn = gbuffer.normal(y, x);
        const Vec3 point(p.x, p.y, p.z), normal(nn.x, nn.y, nn.z);
        const float real_pixel = gbuffer.virtual_surface(y, x) ? 0.f : 1.f;
        const Radiance r = shader.shade(point, normal, (camera_centre - point).normalized(),
                                        scene.materials[gbuffer.material(y, x) - 1u], real_pixel);
        out.real_virtual(y, x) = {r.real_virtual.x(), r.real_virtual.y(), r.real_virtual.z()};
        out.real(y, x) = {r.real.x(), r.real.y(), r.real.z()};
        out.virtual_coverage(y, x) = 1.f - real_pixel;
      }
  }, 4);
  return out;
}

}  // namespace relight::render
