#include "relight/render/vpl/vpl.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <bit>
#include <cmath>
#include <numbers>
#include <utility>

#include "relight/core/error.h"
#include "relight/render/scene/discrete_sampler.h"
#include "relight/render/scene/phong_brdf.h"
#include "relight/render/scene/sampler.h"
#include "relight/render/vpl/cone_search.h"
#include "relight/render/vpl/cone_search_vk.h"
#include "relight/render/vpl/hierarchical_warp.h"
#include "relight/render/vpl/reflective_shadow_map.h"
#include "relight/render/vpl/reflective_shadow_map_vk.h"
#include "scene/surface_shading.h"
#include "vpl/light_sampling.h"
#include "vpl/vpl_budget.h"
#include "vpl/vpl_tracer.h"

namespace relight::render {
namespace {

using namespace vpl_detail;

/// A directional light's n samples: parallel rays from a disk facing the light that covers the
/// scene (flux E area / n each), with the virtual-focus share drawn from the smaller disk over
/// the virtual objects' bounding sphere and the rest rejected there (as for the cone above).
void emit_directional(const MrLight& light, std::size_t index, int n, const BoundingSphere& bounds,
                      const BoundingSphere& virtual_sphere, const VplOptions& options, VplTracer& tracer) {
  if (n <= 0 || bounds.radius <= 0.f) return;
  const Vec3 towards_light = light.direction.normalized();
  const Vec3 plane_point = bounds.centre + 2.f * bounds.radius * towards_light;
  const Disk scene_disk(plane_point, towards_light, bounds.radius);
  std::optional<Disk> focus;
  if (options.virtual_share > 0.f && virtual_sphere.radius > 0.f && n >= 2)
    focus.emplace(virtual_sphere.centre + towards_light * (plane_point - virtual_sphere.centre).dot(towards_light),
                  towards_light, virtual_sphere.radius);
  const int n_focus = focus ? std::max(1, static_cast<int>(std::lround(options.virtual_share * n))) : 0;
  const int n_rest = n - n_focus;
  for (int i = 0; i < n; ++i) {
    Pcg32 rng = Pcg32::for_sample(options.seed, index, static_cast<std::uint64_t>(i));
    const bool in_focus = i < n_focus;
    const Disk& disk = in_focus ? *focus : scene_disk;
    const int stratum_count = in_focus ? n_focus : n_rest;
    const float u1 = (static_cast<float>(in_focus ? i : i - n_focus) + rng.uniform()) / static_cast<float>(stratum_count);
    const Vec3 origin = disk.sample(u1, rng.uniform());
    if (!in_focus && focus && focus->contains(origin)) continue;  // the focus stratum covers it
    tracer.emit(origin, -towards_light, light.intensity * (disk.area() / static_cast<float>(stratum_count)), true,
                light.real, 1, rng);
  }
}

/// Slots per RSM: all to one map, or shared by covered texels (largest remainder), with at least
/// one for a map that covers anything while there are two slots or more.
std::vector<int> rsm_slots(const std::vector<ReflectiveShadowMap>& maps, int n) {
  std::vector<int> slots(maps.size(), 0);
  if (maps.size() == 1) {
    slots[0] = n;
    return slots;
  }
  const auto real = static_cast<double>(maps[0].covered()), virtual_ = static_cast<double>(maps[1].covered());
  if (real + virtual_ <= 0.0) return slots;
  slots[0] = static_cast<int>(std::lround(n * real / (real + virtual_)));
  if (n >= 2 && real > 0.0) slots[0] = std::max(slots[0], 1);
  if (n >= 2 && virtual_ > 0.0) slots[0] = std::min(slots[0], n - 1);
  slots[1] = n - slots[0];
  return slots;
}

/// A spot light's n first-bounce VPLs from its RSMs (VplSource::ReflectiveShadowMaps).
void emit_from_rsms(const MrScene& scene, const RayTracer& tracer, std::size_t index, int n, const VplOptions& options,
                    ReflectiveShadowMapsVk* gpu, VplTracer& vpl_tracer) {
  if (n <= 0) return;
  const MrLight& light = scene.lights[index];
  const std::vector<ReflectiveShadowMap> maps = gpu ? gpu->render(scene, index, options.rsm_size)
                                                    : reflective_shadow_maps_cpu(scene, tracer, index, options.rsm_size);
  const std::vector<int> slots = rsm_slots(maps, n);
  for (std::size_t m = 0; m < maps.size(); ++m) {
    if (slots[m] <= 0) continue;
    const ImportancePyramid pyramid(maps[m].importance(), maps[m].size);
    const auto count = static_cast<std::uint32_t>(slots[m]);
    const std::vector<WarpedTexel> texels = warp_points(pyramid, hammersley_points(count));
    for (std::size_t i = 0; i < texels.size(); ++i) {
      const RsmTexel& texel = maps[m].texels[texels[i].y * static_cast<std::uint32_t>(maps[m].size) + texels[i].x];
      Pcg32 rng = Pcg32::for_sample(options.seed, index, m * count + i);
      // Flags as the ray-traced generator gives them: a real light's real RSM holds both worlds
      // except behind a virtual object, its virtual RSM the real+virtual world only.
      const bool in_real = light.real && (m == 0);
      const bool in_real_virtual = !(light.real && m == 0 && texel.occluded_by_virtual);
      const Vec3 flux = texel.flux / (texels[i].probability * static_cast<float>(count));
      vpl_tracer.add(*texel.hit, texel.direction, flux, in_real_virtual, in_real, 1, rng);
    }
  }
}

}  // namespace

std::vector<double> vpl_flux_per_light(const std::vector<Vpl>& vpls, std::size_t light_count) {
  std::vector<double> flux(light_count, 0.0);
  for (const Vpl& vpl : vpls) {
    // A path that a virtual object splits ends in two VPLs; the real+virtual one counts it once.
    if (vpl.bounce != 1 || !vpl.in_real_virtual || vpl.light >= light_count) continue;
    flux[vpl.light] += luminance(vpl.flux);
  }
  return flux;
}

std::size_t emitter_count(std::span<const Vpl> vpls) {
  const auto first = std::find_if(vpls.begin(), vpls.end(), [](const Vpl& v) { return v.emitter(); });
  if (std::any_of(first, vpls.end(), [](const Vpl& v) { return !v.emitter(); }))
    throw Error("the emitter VPLs must come after every bounce VPL");
  return static_cast<std::size_t>(vpls.end() - first);
}

namespace {

/// The emitter VPL of every light with MrLight::through_vpl (see vpl.h).
void add_emitters(const MrScene& scene, const BoundingSphere& bounds, std::vector<Vpl>& vpls) {
  const float radius = bounds.radius > 0.f ? bounds.radius : 1.f;
  for (std::size_t l = 0; l < scene.lights.size(); ++l) {
    const MrLight& light = scene.lights[l];
    if (!light.through_vpl) continue;
    const Vec3 towards_light = light.direction.normalized();
    Vpl emitter;
    emitter.position = bounds.centre + kEmitterDistance * radius * towards_light;
    emitter.normal = -towards_light;
    emitter.geometric_normal = emitter.normal;
    emitter.incident = towards_light;
    emitter.flux = light.intensity;
    emitter.on_real_surface = light.real;
    emitter.in_real_virtual = true;
    emitter.in_real = light.real;
    emitter.bounce = 0;
    emitter.light = static_cast<std::uint32_t>(l);
    vpls.push_back(emitter);
  }
}

/// The multiple-bounce light source (vpl.h): `n` segments continuing the paths of the previous
/// frame's VPLs of bounce below options.bounces, in directions sampled from the sources' BRDFs.
/// Two strata cover every source once:
///   differential  VPLs on virtual objects or in one world only: the virtual objects' own
///                 bounces, the part of the light the composite shows. Most carry little flux
///                 (the virtual-focus samples of their light), so flux-proportional picking would
///                 give each continuation the stratum's mean flux: a few bright VPLs beside the
///                 object, and blotches. They are picked uniformly instead, each continuation
///                 keeping its source's flux (times count / samples), and get up to
///                 `virtual_share` of the samples - no more than there are of them;
///   rest          the others, picked by flux, stratified: their bounces are mostly real light,
///                 which the differential image only sees where a virtual object blocks it.
bool continues_path(const Vpl& source, const VplOptions& options) {
  return !source.emitter() && source.bounce < options.bounces && luminance(source.flux) > 0.f;
}

void emit_from_previous_vpls(int n, const VplOptions& options, VplTracer& tracer) {
  const std::span<const Vpl> sources = options.previous_vpls;
  DiscreteSampler differential, rest;
  for (std::size_t i = 0; i < sources.size(); ++i) {
    const Vpl& source = sources[i];
    if (!continues_path(source, options)) continue;
    const bool differs = !source.on_real_surface || source.in_real != source.in_real_virtual;
    if (differs)
      differential.add(i, 1.0);
    else
      rest.add(i, static_cast<double>(luminance(source.flux)));
  }
  if (n <= 0 || differential.size() + rest.size() == 0) return;
  int n_differential = 0;
  if (rest.size() == 0) {
    n_differential = n;
  } else if (differential.size() > 0) {
    const auto wanted = static_cast<int>(std::lround(options.virtual_share * n));
    n_differential = std::min(std::max(wanted, 1), static_cast<int>(differential.size()));
    if (n >= 2) n_differential = std::min(n_differential, n - 1);
  }
  for (int i = 0; i < n; ++i) {
    // A stream of its own: light indices never reach 2^32 - 1.
    Pcg32 rng = Pcg32::for_sample(options.seed, 0xffffffffu, static_cast<std::uint64_t>(i));
    const bool in_differential = i < n_differential;
    const int stratum_count = in_differential ? n_differential : n - n_differential;
    const int j = in_differential ? i : i - n_differential;
    const auto [index, probability] =
        (in_differential ? differential : rest).pick((j + rng.uniform()) / static_cast<double>(stratum_count));
    if (!(probability > 0.0)) continue;
    const Vpl& source = sources[index];
    const float u1 = rng.uniform(), u2 = rng.uniform();
    const auto sample = sample_phong(options.previous_surfaces[index], source.normal, source.incident, u1, u2);
    // As a path continued in its own frame (vpl_tracer.h): above the geometric surface only.
    if (!sample || sample->wi.dot(source.geometric_normal) <= 0.f) continue;
    const Vec3 flux = source.flux.cwiseProduct(sample->weight) / static_cast<float>(probability * stratum_count);
    const float offset = 1e-4f * (1.f + source.position.cwiseAbs().maxCoeff());
    tracer.set_light(source.light);
    tracer.emit(source.position + offset * source.geometric_normal, sample->wi, flux, source.in_real_virtual,
                source.in_real, source.bounce + 1, rng);
  }
}

}  // namespace

std::vector<Phong> vpl_surfaces(const MrScene& scene, std::span<const Vpl> vpls) {
  std::vector<Phong> surfaces;
  surfaces.reserve(vpls.size());
  for (const Vpl& vpl : vpls) surfaces.push_back(vpl.emitter() ? Phong{} : vpl_phong(scene, vpl));
  return surfaces;
}

std::vector<Vpl> generate_vpls(const MrScene& scene, const RayTracer& tracer, const VplOptions& options,
                               const VplGpu& gpu) {
  if (options.count < 0) throw Error("the VPL count must not be negative");
  if (options.bounces < 1) throw Error("VPLs need at least one bounce");
  if (options.bounce_method == BounceMethod::PointCone &&
      (!(options.cone_half_angle_deg > 0.f && options.cone_half_angle_deg < 90.f) || options.cone_points < 1 ||
       options.cone_points > 65536))
    throw Error("the bounce cone needs an angle in (0, 90) degrees and 1 to 65536 points per layer");
  if (options.source == VplSource::ReflectiveShadowMaps &&
      (options.rsm_size < 1 || options.rsm_size > 4096 || !std::has_single_bit(static_cast<unsigned>(options.rsm_size))))
    throw Error("the RSM size must be a power of two in [1, 4096]");
  const bool from_previous = options.bounce_method == BounceMethod::PreviousFrame;
  if (from_previous && !(options.bounce_share > 0.f && options.bounce_share < 1.f))
    throw Error("the share of VPLs that continue the previous frame's must be in (0, 1)");
  if (options.previous_surfaces.size() != options.previous_vpls.size())
    throw Error("the previous frame's VPLs and their surfaces differ in number");
  std::vector<Vpl> vpls;
  VplTracer vpl_tracer(scene, tracer, options, vpls, gpu.cone_search);
  if (options.virtual_share < 0.f || options.virtual_share >= 1.f) throw Error("the virtual VPL share must be in [0, 1)");
  const BoundingSphere bounds = bounding_sphere(scene);
  // The multiple-bounce light source's share of the samples, once there are VPLs to continue.
  const bool continues = from_previous && std::any_of(options.previous_vpls.begin(), options.previous_vpls.end(),
                                                      [&](const Vpl& v) { return continues_path(v, options); });
  const int continued = continues ? static_cast<int>(std::lround(options.bounce_share * options.count)) : 0;
  VplOptions primary = options;
  primary.count = options.count - continued;
  const std::vector<int> budget = light_budget(scene, bounds, primary);
  const BoundingSphere virtual_sphere = virtual_bounds(scene);
  for (std::size_t l = 0; l < scene.lights.size(); ++l) {
    const MrLight& light = scene.lights[l];
    vpl_tracer.set_light(l);
    if (light.kind == LightKind::Directional) {
      emit_directional(light, l, budget[l], bounds, virtual_sphere, options, vpl_tracer);
      continue;
    }
    if (options.source == VplSource::ReflectiveShadowMaps && has_reflective_shadow_maps(light)) {
      emit_from_rsms(scene, tracer, l, budget[l], options, gpu.reflective_shadow_maps, vpl_tracer);
      continue;
    }
    const std::optional<Cone> cone = options.virtual_share > 0.f ? cone_towards(virtual_sphere, light.position) : std::nullopt;
    const int n = budget[l];
    const int n_cone = cone && n >= 2 ? std::max(1, static_cast<int>(std::lround(options.virtual_share * n))) : 0;
    const int n_rest = n - n_cone;
    for (int i = 0; i < n; ++i) {
      Pcg32 rng = Pcg32::for_sample(options.seed, l, static_cast<std::uint64_t>(i));
      if (i < n_cone) {
        const float u1 = (static_cast<float>(i) + rng.uniform()) / static_cast<float>(n_cone);  // stratified
        const Vec3 direction = cone->sample(u1, rng.uniform());
        const float falloff = light.kind == LightKind::Spot ? detail::spot_falloff(light, direction) : 1.f;
        vpl_tracer.emit(light.position, direction, light.intensity * (falloff * cone->solid_angle / static_cast<float>(n_cone)),
                        true, light.real, 1, rng);
        continue;
      }
      const int j = i - n_cone;
      const float u1 = (static_cast<float>(j) + rng.uniform()) / static_cast<float>(n_rest);  // stratified
      const LightSample sample = sample_light_direction(light, u1, rng.uniform());
      if (cone && n_cone > 0 && cone->contains(sample.direction)) continue;  // the other stratum covers it
      vpl_tracer.emit(light.position, sample.direction, sample.intensity_over_pdf / static_cast<float>(n_rest), true,
                      light.real, 1, rng);
    }
  }
  emit_from_previous_vpls(continued, options, vpl_tracer);
  vpl_tracer.finish();
  add_emitters(scene, bounds, vpls);
  return vpls;
}

}  // namespace relight::render
