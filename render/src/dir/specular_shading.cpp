#include "relight/render/dir/specular_shading.h"

#include <algorithm>
#include <array>

#include "relight/core/error.h"

namespace relight::render {

namespace detail {
// dir_cpu.cpp: shade_dir_from_maps with a view point per pixel (`eyes`) instead of the camera's.
DifferentialImages shade_from_maps(const GBuffer& gbuffer, const MrScene& scene, const Eigen::Vector3f& camera_centre,
                                   const PositionMap* eyes, const ShadowLayout& layout,
                                   std::span<const float> shadow_atlas, std::span<const Vpl> vpls,
                                   std::span<const float> ism_atlas, const IsmPointPools& ism_points,
                                   const DirRenderOptions& options);
}  // namespace detail

namespace {

/// Per channel: a branch's weight times its light.
Float3 times(const Float3& a, const Float3& b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }

/// L'_r at the real specular pixels (a real mirror or glass, add_real_model) from branches
/// traced in the real world. Eq. 4 gives L'_r nothing where a branch ends on a virtual object,
/// so the composite CI + (L'_rv - L'_r) would add the object's light to the camera's reflection
/// of what stands behind it; the real-world branch sees that surface, so Delta L' takes it out
/// and the object replaces it - better than the paper, which has no such branch. Only where the
/// scene has virtual meshes and a real specular surface is in view.
void put_real_world_reflections(DifferentialImages& images, const RayTracer& tracer, const MrCamera& camera,
                                const GBuffer& gbuffer, const ShadowLayout& layout, std::span<const float> shadow_atlas,
                                std::span<const Vpl> vpls, std::span<const float> ism_atlas,
                                const IsmPointPools& ism_points, const DirRenderOptions& options,
                                std::span<const CausticPhotons> photons) {
  const MrScene& scene = tracer.scene();
  if (std::none_of(scene.meshes.begin(), scene.meshes.end(), [](const TriangleMesh& m) { return !m.real; })) return;
  // Most scenes' mirrors and glass are virtual: no second pair of full-size G-buffers for them.
  bool real_specular_in_view = false;
  for (std::size_t i = 0; i < gbuffer.material.size() && !real_specular_in_view; ++i) {
    const std::uint16_t label = gbuffer.material.pixels()[i];
    real_specular_in_view =
        label != 0 && !gbuffer.virtual_surface.pixels()[i] && scene.materials[label - 1u].specular.specular();
  }
  if (!real_specular_in_view) return;
  const SpecularGBuffers real_world =
      specular_gbuffers_cpu(tracer, camera, gbuffer, {.threads = options.shading.threads, .real_world = true});
  if (real_world.pixels == 0) return;
  const SpecularLight seen =
      shade_specular_from_maps(real_world, scene, layout, shadow_atlas, vpls, ism_atlas, ism_points, options, photons);
  const bool indirect = !images.indirect_real.empty();
  for (std::size_t i = 0; i < images.real.size(); ++i) {
    if (!real_world.specular.pixels()[i]) continue;
    images.real.pixels()[i] = seen.light.real.pixels()[i];
    if (indirect) images.indirect_real.pixels()[i] = seen.light.indirect_real.pixels()[i];
  }
}

}  // namespace

SpecularLight shade_specular_from_maps(const SpecularGBuffers& specular, const MrScene& scene,
                                       const ShadowLayout& layout, std::span<const float> shadow_atlas,
                                       std::span<const Vpl> vpls, std::span<const float> ism_atlas,
                                       const IsmPointPools& ism_points, const DirRenderOptions& options,
                                       std::span<const CausticPhotons> photons) {
  const int width = specular.specular.width(), height = specular.specular.height();
  SpecularLight out{{RadianceImage(width, height), RadianceImage(width, height), CoverageImage(width, height), 1,
                     RadianceImage(width, height), RadianceImage(width, height)},
                    {},
                    {}};
  DifferentialImages& sum = out.light;
  for (const SpecularBranch* branch : {&specular.reflected, &specular.refracted}) {
    DifferentialImages light = detail::shade_from_maps(branch->gbuffer, scene, Eigen::Vector3f::Zero(), &branch->eye,
                                                       layout, shadow_atlas, vpls, ism_atlas, ism_points, options);
    for (const CausticPhotons& some : photons)
      add_caustic_light(light, branch->gbuffer, scene, some, Eigen::Vector3f::Zero(), &branch->eye, nullptr,
                        options.shading.threads);
    for (std::size_t i = 0; i < sum.real_virtual.size(); ++i) {
      if (!specular.specular.pixels()[i]) continue;
      const Float3& w = branch->weight.pixels()[i];
      sum.real_virtual.pixels()[i] += times(w, light.real_virtual.pixels()[i]);
      sum.real.pixels()[i] += times(w, light.real.pixels()[i]);
      sum.indirect_real_virtual.pixels()[i] += times(w, light.indirect_real_virtual.pixels()[i]);
      sum.indirect_real.pixels()[i] += times(w, light.indirect_real.pixels()[i]);
    }
    (branch == &specular.reflected ? out.reflected_real : out.refracted_real) = std::move(light.real);
  }
  return out;
}

void put_specular_light(DifferentialImages& images, const DifferentialImages& specular_light,
                        const SpecularGBuffers& specular) {
  if (images.real_virtual.width() != specular.specular.width() ||
      images.real_virtual.height() != specular.specular.height())
    throw Error("put_specular_light: the images and the specular G-buffers differ in size");
  const bool indirect = !images.indirect_real_virtual.empty();
  for (std::size_t i = 0; i < images.real_virtual.size(); ++i) {
    if (!specular.specular.pixels()[i]) continue;
    images.real_virtual.pixels()[i] = specular_light.real_virtual.pixels()[i];
    images.real.pixels()[i] = specular_light.real.pixels()[i];
    if (!indirect) continue;
    images.indirect_real_virtual.pixels()[i] = specular_light.indirect_real_virtual.pixels()[i];
    images.indirect_real.pixels()[i] = specular_light.indirect_real.pixels()[i];
  }
}

SpecularBackProjection add_specular_light(DifferentialImages& images, const RayTracer& tracer, const MrCamera& camera,
                                          const GBuffer& gbuffer, const ShadowLayout& layout,
                                          std::span<const float> shadow_atlas, std::span<const Vpl> vpls,
                                          std::span<const float> ism_atlas, const IsmPointPools& ism_points,
                                          const DirRenderOptions& options) {
  const int threads = options.shading.threads;
  const std::array<CausticPhotons, 2> photons{trace_caustic_photons(tracer, options.caustics, threads),
                                              trace_vpl_caustic_photons(tracer, vpls, options.caustics, threads)};
  for (const CausticPhotons& some : photons)
    add_caustic_light(images, gbuffer, tracer.scene(), some, camera.camera_to_world.translation().cast<float>(),
                      nullptr, nullptr, threads);
  const SpecularGBuffers specular = specular_gbuffers_cpu(tracer, camera, gbuffer, {.threads = threads});
  if (specular.pixels == 0) return {};
  const SpecularLight light = shade_specular_from_maps(specular, tracer.scene(), layout, shadow_atlas, vpls, ism_atlas,
                                                       ism_points, options, photons);
  put_specular_light(images, light.light, specular);
  put_real_world_reflections(images, tracer, camera, gbuffer, layout, shadow_atlas, vpls, ism_atlas, ism_points,
                             options, photons);
  return back_project(specular, light.reflected_real, light.refracted_real, tracer, camera);
}

}  // namespace relight::render
