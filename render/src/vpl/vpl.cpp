#include "relight/render/vpl/vpl.h"

#include <Eigen/Geometry>
#include <bit>
#include <cmath>
#include <numbers>
#include <utility>

#include "relight/core/error.h"
#include "relight/render/dir/ism.h"  // sample_ism_points: the point pools the cone search reads
#include "relight/render/vpl/cone_search.h"
#include "relight/render/vpl/cone_search_vk.h"
#include "relight/render/vpl/hierarchical_warp.h"
#include "relight/render/scene/phong_brdf.h"
#include "relight/render/vpl/reflective_shadow_map.h"
#include "relight/render/vpl/reflective_shadow_map_vk.h"
#include "relight/render/scene/sampler.h"
#include "scene/surface_shading.h"

namespace relight::render {
namespace {

using Vec3 = Eigen::Vector3f;
constexpr float kPi = std::numbers::pi_v<float>;

float luminance(const Vec3& c) { return 0.2126f * c.x() + 0.7152f * c.y() + 0.0722f * c.z(); }

/// Solid angle a light emits into (the spot's cone up to its outer edge).
float emission_solid_angle(const MrLight& light) {
  return light.kind == LightKind::Spot ? 2.f * kPi * (1.f - light.cos_outer) : 4.f * kPi;
}

bool emits_vpls(const MrLight&) { return true; }

struct LightSample {
  Vec3 direction;
  Vec3 intensity_over_pdf;
};

/// Uniform over the sphere (point light) or the spot's cone; u1 is stratified by the caller.
LightSample sample_light_direction(const MrLight& light, float u1, float u2) {
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

BoundingSphere virtual_bounds(const MrScene& scene) {
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

std::optional<Cone> cone_towards(const BoundingSphere& sphere, const Vec3& from) {
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

/// A continued path segment waiting for the point-cone search of its bounce.
struct PendingSegment {
  Vec3 origin, normal, direction, flux;
  bool in_real_virtual = true, in_real = true;
  int bounce = 2;
  std::uint32_t light = 0, parent = Vpl::kNoParent;
  Pcg32 rng;
};

/// BounceMethod::PointCone's search (cone_search.h) over each layer's points, for all segments
/// of one bounce at once: on the GPU when there is one, else on the CPU.
class ConeSearch {
 public:
  ConeSearch(const MrScene& scene, const VplOptions& options, ConeSearchVk* gpu)
      : points_(sample_ism_points(scene, {.points_per_vpl = options.cone_points, .pool_factor = 1, .seed = options.seed})),
        half_angle_deg_(options.cone_half_angle_deg),
        gpu_(gpu) {}

  struct Hits {
    std::optional<SurfaceHit> real, virtual_hit;  ///< the virtual one only when nearer
  };

  [[nodiscard]] std::vector<Hits> resolve(const std::vector<PendingSegment>& segments) const {
    std::vector<ConeQuery> queries;
    queries.reserve(segments.size());
    for (const PendingSegment& s : segments) queries.push_back({s.origin, s.normal, s.direction});
    const std::vector<ConeHit> real = search(points_.real, queries);
    for (std::size_t i = 0; i < queries.size(); ++i) queries[i].max_t = real[i].t;
    const std::vector<ConeHit> virtual_hits = search(points_.virtual_points, queries);
    std::vector<Hits> hits(segments.size());
    for (std::size_t i = 0; i < segments.size(); ++i) {
      hits[i].real = surface_hit(points_.real, segments[i], real[i], true);
      hits[i].virtual_hit = surface_hit(points_.virtual_points, segments[i], virtual_hits[i], false);
    }
    return hits;
  }

 private:
  [[nodiscard]] std::vector<ConeHit> search(const std::vector<IsmPoint>& points,
                                            const std::vector<ConeQuery>& queries) const {
    if (!gpu_ || points.empty()) return cone_search_cpu(points, queries, half_angle_deg_);
    gpu_->set_points(points);
    return gpu_->search(queries, half_angle_deg_);
  }

  static std::optional<SurfaceHit> surface_hit(const std::vector<IsmPoint>& points, const PendingSegment& segment,
                                               const ConeHit& hit, bool real) {
    if (hit.point == ConeHit::kNone) return std::nullopt;
    const IsmPoint& point = points[hit.point];
    return SurfaceHit{hit.t, segment.origin + hit.t * segment.direction, point.normal, point.normal, point.material,
                      real};
  }

  IsmPointPools points_;
  float half_angle_deg_;
  ConeSearchVk* gpu_;
};

class VplTracer {
 public:
  VplTracer(const MrScene& scene, const RayTracer& tracer, const VplOptions& options, std::vector<Vpl>& out,
            ConeSearchVk* gpu)
      : scene_(scene), tracer_(tracer), options_(options), out_(out) {
    if (options.bounces > 1 && options.bounce_method == BounceMethod::PointCone) cone_.emplace(scene, options, gpu);
  }

  /// The primary light whose paths the following emit() calls follow.
  void set_light(std::size_t light) { light_ = static_cast<std::uint32_t>(light); }

  /// Follows one light path segment and records the VPL(s) it ends in.
  void emit(const Vec3& origin, const Vec3& direction, const Vec3& flux, bool in_real_virtual, bool in_real, int bounce,
            Pcg32& rng, std::uint32_t parent = Vpl::kNoParent) {
    if (flux.maxCoeff() <= 0.f || (!in_real_virtual && !in_real)) return;
    const std::optional<SurfaceHit> real = tracer_.intersect(Layer::Real, origin, direction);
    const std::optional<SurfaceHit> virtual_hit =
        tracer_.intersect(Layer::Virtual, origin, direction, real ? real->t : std::numeric_limits<float>::infinity());
    record(real, virtual_hit, direction, flux, in_real_virtual, in_real, bounce, rng, parent);
  }

  /// BounceMethod::PointCone: resolves the waiting segments bounce by bounce until none is left.
  void finish() {
    while (!pending_.empty()) {
      const std::vector<PendingSegment> segments = std::exchange(pending_, {});
      const std::vector<ConeSearch::Hits> hits = cone_->resolve(segments);
      for (std::size_t i = 0; i < segments.size(); ++i) {
        PendingSegment s = segments[i];
        light_ = s.light;
        record(hits[i].real, hits[i].virtual_hit, s.direction, s.flux, s.in_real_virtual, s.in_real, s.bounce, s.rng,
               s.parent);
      }
    }
  }

  /// The VPL(s) a path segment ends in, given what it reached in each layer (the virtual hit
  /// only when nearer than the real one).
  void record(const std::optional<SurfaceHit>& real, const std::optional<SurfaceHit>& virtual_hit, const Vec3& direction,
              const Vec3& flux, bool in_real_virtual, bool in_real, int bounce, Pcg32& rng, std::uint32_t parent) {
    if (virtual_hit) {
      // The two worlds part here: the virtual surface is lit with the virtual objects present,
      // the real surface behind it only without them.
      add(*virtual_hit, direction, flux, in_real_virtual, false, bounce, rng, parent);
      if (real) add(*real, direction, flux, false, in_real, bounce, rng, parent);
    } else if (real) {
      add(*real, direction, flux, in_real_virtual, in_real, bounce, rng, parent);
    }
  }

  /// Records a VPL at `hit`, lit along `direction`, and continues its path.
  void add(const SurfaceHit& hit, const Vec3& direction, const Vec3& flux, bool in_real_virtual, bool in_real, int bounce,
           Pcg32& rng, std::uint32_t parent = Vpl::kNoParent) {
    if (!in_real_virtual && !in_real) return;
    Vpl vpl;
    vpl.position = hit.point;
    vpl.incident = -direction;
    const Vec3 geometric = hit.geometric_normal.dot(vpl.incident) < 0.f ? Vec3(-hit.geometric_normal) : hit.geometric_normal;
    vpl.normal = hit.shading_normal.dot(geometric) < 0.f ? Vec3(-hit.shading_normal) : hit.shading_normal;
    if (vpl.normal.dot(vpl.incident) <= 0.f) vpl.normal = geometric;
    vpl.flux = flux;
    vpl.material = hit.material;
    vpl.on_real_surface = hit.real;
    vpl.in_real_virtual = in_real_virtual;
    vpl.in_real = in_real;
    vpl.bounce = bounce;
    vpl.light = light_;
    vpl.parent = parent;
    const auto index = static_cast<std::uint32_t>(out_.size());
    out_.push_back(vpl);
    if (bounce >= options_.bounces) return;
    // Continue the light path by sampling the VPL's BRDF (reciprocity: wo = where light came from).
    const float u1 = rng.uniform(), u2 = rng.uniform();
    const auto sample = sample_phong(scene_.materials[vpl.material], vpl.normal, vpl.incident, u1, u2);
    if (!sample || sample->wi.dot(geometric) <= 0.f) return;
    const Vec3 next_flux = flux.cwiseProduct(sample->weight);
    if (cone_) {
      if (next_flux.maxCoeff() > 0.f)
        pending_.push_back({vpl.position, geometric, sample->wi, next_flux, vpl.in_real_virtual, vpl.in_real, bounce + 1,
                            light_, index, rng});
      return;
    }
    const float offset = 1e-4f * (1.f + vpl.position.cwiseAbs().maxCoeff());
    emit(vpl.position + offset * geometric, sample->wi, next_flux, vpl.in_real_virtual, vpl.in_real, bounce + 1, rng,
         index);
  }

 private:
  const MrScene& scene_;
  const RayTracer& tracer_;
  const VplOptions& options_;
  std::vector<Vpl>& out_;
  std::uint32_t light_ = 0;
  std::optional<ConeSearch> cone_;
  std::vector<PendingSegment> pending_;
};

double power_weight(const MrLight& light, const BoundingSphere& bounds) {
  // Power: intensity times solid angle, or for a directional light irradiance times the area of
  // the scene's cross-section.
  const float extent = light.kind == LightKind::Directional ? kPi * std::max(bounds.radius, 0.f) * std::max(bounds.radius, 0.f)
                                                            : emission_solid_angle(light);
  return std::max(0.f, luminance(light.intensity)) * extent;
}

/// The weights of VplBudget (vpl.h) for the lights that emit VPLs; 0 for the others.
std::vector<double> budget_weights(const MrScene& scene, const BoundingSphere& bounds, const VplOptions& options) {
  const std::size_t n = scene.lights.size();
  std::vector<double> weight(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    const MrLight& light = scene.lights[i];
    if (!emits_vpls(light)) continue;
    switch (options.budget) {
      case VplBudget::Equal: weight[i] = 1.0; break;
      case VplBudget::ByPower:
      case VplBudget::ByPreviousFlux: weight[i] = power_weight(light, bounds); break;
      case VplBudget::ByWeight: weight[i] = i < options.light_weights.size() ? options.light_weights[i] : 1.0; break;
    }
  }
  if (options.budget != VplBudget::ByPreviousFlux) return weight;
  // Lights without last frame's flux keep their power weight, scaled by the ratio of flux to
  // power of the lights that have one.
  double flux_sum = 0.0, power_sum = 0.0;
  for (std::size_t i = 0; i < n && i < options.previous_flux.size(); ++i) {
    if (weight[i] <= 0.0) continue;
    flux_sum += std::max(0.0, options.previous_flux[i]);
    power_sum += weight[i];
  }
  if (flux_sum <= 0.0) return weight;  // nothing reached a surface last frame: by power
  const double scale = flux_sum / power_sum;
  double mean = 0.0, emitting = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (weight[i] <= 0.0) continue;
    weight[i] = i < options.previous_flux.size() ? std::max(0.0, options.previous_flux[i]) : weight[i] * scale;
    mean += weight[i];
    emitting += 1.0;
  }
  mean /= emitting;
  for (std::size_t i = 0; i < n; ++i) {
    if (emits_vpls(scene.lights[i])) weight[i] = std::max(weight[i], mean / 16.0);
  }
  return weight;
}

/// Light samples per light, by the weights of the budget.
std::vector<int> light_budget(const MrScene& scene, const BoundingSphere& bounds, const VplOptions& options) {
  const std::vector<double> weight = budget_weights(scene, bounds, options);
  double total = 0.0;
  for (double w : weight) total += std::max(0.0, w);
  std::vector<int> count(scene.lights.size(), 0);
  if (total <= 0.0) return count;
  // Largest remainder, so that the shares add up to options.count exactly.
  int given = 0;
  std::vector<std::pair<double, std::size_t>> remainder;
  for (std::size_t i = 0; i < weight.size(); ++i) {
    const double exact = options.count * std::max(0.0, weight[i]) / total;
    count[i] = static_cast<int>(std::floor(exact));
    given += count[i];
    remainder.emplace_back(exact - count[i], i);
  }
  std::sort(remainder.begin(), remainder.end(), std::greater<>());
  for (int i = 0; i < options.count - given; ++i) ++count[remainder[static_cast<std::size_t>(i) % remainder.size()].second];
  return count;
}

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
  std::vector<Vpl> vpls;
  VplTracer vpl_tracer(scene, tracer, options, vpls, gpu.cone_search);
  if (options.virtual_share < 0.f || options.virtual_share >= 1.f) throw Error("the virtual VPL share must be in [0, 1)");
  const BoundingSphere bounds = bounding_sphere(scene);
  const std::vector<int> budget = light_budget(scene, bounds, options);
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
  vpl_tracer.finish();
  return vpls;
}

}  // namespace relight::render
