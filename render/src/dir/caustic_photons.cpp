#include "relight/render/dir/caustic_photons.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "relight/core/parallel.h"
#include "relight/lights/importance_sampling.h"
#include "relight/render/scene/discrete_sampler.h"
#include "relight/render/scene/luminance.h"
#include "relight/render/scene/phong_brdf.h"
#include "relight/render/scene/sampler.h"
#include "relight/render/scene/specular_bsdf.h"
#include "scene/caustic_emission.h"
#include "scene/surface_shading.h"

namespace relight::render {
namespace {

using Vec3 = Eigen::Vector3f;

/// Mixed into the seed so that photons draw other numbers than the VPLs, and the VPLs' photons
/// other numbers than the lights'.
constexpr std::uint64_t kPhotonSeed = 0x3d9f2a61c4b8e057ull;
constexpr std::uint64_t kVplPhotonSeed = 0x8b51c0e7a4f3d926ull;
/// Photon paths per parallel work item, merged in order: the result does not depend on threads.
constexpr int kPathsPerChunk = 1024;

/// One photon path in one world; the photon it leaves, if it reaches a diffuse surface through
/// at least one specular vertex.
std::optional<CausticPhoton> follow(const RayTracer& tracer, const detail::Emission& emission, bool real_world,
                                    Pcg32 rng, int max_vertices) {
  const MrScene& scene = tracer.scene();
  Vec3 origin = emission.origin, direction = emission.direction, flux = emission.beta;
  const SpecularMaterial* medium = nullptr;
  std::uint32_t rays = 0;
  for (int vertex = 0;; ++vertex) {
    const std::optional<SurfaceHit> hit = detail::nearest_hit(tracer, origin, direction, !real_world, rays);
    if (!hit) return std::nullopt;
    if (medium) flux = flux.cwiseProduct(beer_lambert(*medium, hit->t));
    const detail::Vertex v = detail::make_vertex(*hit, direction, scene);
    if (!v.specular) {
      if (vertex == 0) return std::nullopt;  // direct light: the shadow maps' share
      return CausticPhoton{v.point, v.wo, v.shading_normal, flux, real_world};
    }
    if (vertex >= max_vertices) return std::nullopt;
    const std::optional<SpecularSample> sample =
        sample_specular(*v.specular, v.outward, v.wo, rng.uniform(), Transport::Importance);
    if (!sample) return std::nullopt;
    flux = flux.cwiseProduct(sample->weight);
    if (sample->transmitted) medium = v.outward.dot(v.wo) >= 0.f ? v.specular : nullptr;
    origin = detail::offset_origin(v, sample->wi);
    direction = sample->wi;
  }
}

/// Where a photon path starts and in which worlds it is traced.
struct PhotonSource {
  detail::Emission emission;
  bool in_real_virtual = true;
  bool in_real = true;
};

/// `total` photon paths, path i started by emit(i, rng) (nullopt: none), each traced in the worlds
/// of its source with the same random numbers: where the path meets only real surfaces, the two
/// photons are the same and cancel in L_rv - L_r. Chunks are merged in order, so the result
/// does not depend on the thread count.
template <class Emit>
std::vector<CausticPhoton> trace_paths(const RayTracer& tracer, std::size_t total, std::uint64_t seed, int max_vertices,
                                       int threads, const Emit& emit) {
  const auto chunks = static_cast<int>((total + kPathsPerChunk - 1) / kPathsPerChunk);
  std::vector<std::vector<CausticPhoton>> found(static_cast<std::size_t>(chunks));
  parallel_rows(
      chunks, threads,
      [&](int begin, int end) {
        for (int chunk = begin; chunk < end; ++chunk) {
          const std::size_t first = static_cast<std::size_t>(chunk) * kPathsPerChunk;
          const std::size_t last = std::min(total, first + kPathsPerChunk);
          for (std::size_t i = first; i < last; ++i) {
            Pcg32 rng = Pcg32::for_sample(seed, i, 0);
            const std::optional<PhotonSource> source = emit(i, rng);
            if (!source) continue;
            for (const bool real_world : {false, true}) {
              if (!(real_world ? source->in_real : source->in_real_virtual)) continue;
              if (auto photon = follow(tracer, source->emission, real_world, rng, max_vertices))
                found[static_cast<std::size_t>(chunk)].push_back(*photon);
            }
          }
        }
      },
      1);
  std::vector<CausticPhoton> photons;
  for (std::vector<CausticPhoton>& chunk : found) photons.insert(photons.end(), chunk.begin(), chunk.end());
  return photons;
}

}  // namespace

CausticPhotons::CausticPhotons(std::vector<CausticPhoton> photons, const PhotonKernel& kernel, bool indirect)
    : photons_(std::move(photons)), radius_(kernel.radius), indirect_(indirect) {
  const auto cell_of = [this](const Vec3& p) { return (p / radius_).array().floor().cast<int>().eval(); };
  // Photons per cell and world (index 0: L_rv's, 1: L_r's).
  std::unordered_map<std::int64_t, std::array<int, 2>> counts;
  for (std::size_t i = 0; i < photons_.size(); ++i) {
    const Eigen::Vector3i cell = cell_of(photons_[i].position);
    const std::int64_t k = key(cell.x(), cell.y(), cell.z());
    cells_[k].push_back(static_cast<std::uint32_t>(i));
    ++counts[k][photons_[i].real_world ? 1 : 0];
  }
  // Each cell's disc radius per world, from the photons of its 3 x 3 x 3 block: a disc holding
  // `neighbours` of them where they cover (3 radius)^2.
  const float min_radius = std::clamp(kernel.min_radius, 0.f, radius_);
  const float block_area = 9.f * radius_ * radius_;
  std::unordered_map<std::int64_t, std::array<float, 2>> radii;
  for (const auto& [k, unused] : counts) {
    const Eigen::Vector3i cell = cell_of(photons_[cells_[k].front()].position);
    std::array<int, 2> block{0, 0};
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const auto found = counts.find(key(cell.x() + dx, cell.y() + dy, cell.z() + dz));
          if (found == counts.end()) continue;
          block[0] += found->second[0];
          block[1] += found->second[1];
        }
    std::array<float, 2>& r = radii[k];
    for (int world = 0; world < 2; ++world) {
      const float wanted = std::sqrt(static_cast<float>(kernel.neighbours) * block_area /
                                     (std::numbers::pi_v<float> * static_cast<float>(std::max(block[world], 1))));
      r[static_cast<std::size_t>(world)] = std::clamp(wanted, min_radius, radius_);
    }
  }
  for (CausticPhoton& q : photons_) {
    const Eigen::Vector3i cell = cell_of(q.position);
    q.radius = radii[key(cell.x(), cell.y(), cell.z())][q.real_world ? 1 : 0];
  }
}

std::int64_t CausticPhotons::key(int x, int y, int z) const {
  // 21 bits a coordinate: cells of a centimetre reach +-10 km.
  const auto part = [](int v) { return static_cast<std::int64_t>(v & 0x1fffff); };
  return part(x) | (part(y) << 21) | (part(z) << 42);
}

CausticPhotons trace_caustic_photons(const RayTracer& tracer, const CausticOptions& options, int threads) {
  const MrScene& scene = tracer.scene();
  const BoundingSphere target = bounding_sphere(scene, SceneMeshes::Specular);
  if (options.photons_per_light <= 0 || target.radius <= 0.f || scene.lights.empty()) return {};
  const BoundingSphere whole = bounding_sphere(scene, SceneMeshes::All);
  const auto per_light = static_cast<std::size_t>(options.photons_per_light);
  const float inv_paths = 1.f / static_cast<float>(per_light);
  // Each light's first rays are a rotated Hammersley set over the cone (or disc) around the
  // specular objects rather than independent numbers: the set covers the cone evenly, so the
  // caustic's density is not blotched by clusters and gaps of random directions. Every light
  // gets as many (measured: shares in proportion to the flux each light sends at the objects
  // raised the bench's caustic error from 0.227 to 0.243 - the error is relative, and a dim
  // light's caustic in a dark corner counts as much as the key light's).
  std::vector<std::array<float, 2>> shifts;
  for (std::size_t l = 0; l < scene.lights.size(); ++l) {
    Pcg32 rng = Pcg32::for_sample(options.seed ^ kPhotonSeed, l, 1);
    shifts.push_back({rng.uniform(), rng.uniform()});
  }
  return {
      trace_paths(tracer, per_light * scene.lights.size(), options.seed ^ kPhotonSeed, options.max_vertices, threads,
                  [&](std::size_t i, Pcg32&) -> std::optional<PhotonSource> {
                    const std::size_t l = i / per_light;
                    const MrLight& light = scene.lights[l];
                    const auto [u1, u2] = lights::hammersley_point(static_cast<std::uint32_t>(i % per_light), inv_paths,
                                                                   shifts[l][0], shifts[l][1]);
                    std::optional<detail::Emission> emission = detail::emit_towards(light, target, whole, u1, u2);
                    if (!emission) return std::nullopt;
                    emission->beta *= inv_paths;
                    return PhotonSource{*emission, true, light.real};
                  }),
      PhotonKernel{options.radius, options.min_radius, options.neighbours}};
}

CausticPhotons trace_vpl_caustic_photons(const RayTracer& tracer, std::span<const Vpl> vpls,
                                         const CausticOptions& options, int threads) {
  const MrScene& scene = tracer.scene();
  const BoundingSphere target = bounding_sphere(scene, SceneMeshes::Specular);
  if (options.vpl_photons <= 0 || target.radius <= 0.f) return {};
  // Each VPL's share: the luminance of its flux times the solid angle of the cone around the
  // specular objects and the largest cosine to its normal inside that cone.
  DiscreteSampler sources;
  for (std::size_t v = 0; v < vpls.size(); ++v) {
    const Vpl& vpl = vpls[v];
    if (vpl.emitter()) continue;
    const Vec3 to_target = target.centre - vpl.position;
    const float distance = to_target.norm();
    double share = 4.0 * std::numbers::pi;
    if (distance > target.radius) {
      const float sin_max = target.radius / distance;
      const float cos_max = std::sqrt(std::max(0.f, 1.f - sin_max * sin_max));
      const float facing = std::min(1.f, vpl.normal.dot(to_target / distance) + sin_max);
      share = 2.0 * std::numbers::pi * (1.0 - cos_max) * std::max(0.f, facing);
    }
    sources.add(v, share * static_cast<double>(luminance(vpl.flux)));
  }
  if (sources.size() == 0) return {};
  const auto total = static_cast<std::size_t>(options.vpl_photons);
  // A VPL's photons are a run of consecutive indices (the pick is stratified by index), and the
  // Halton points of any such run cover its cone evenly.
  Pcg32 shift_rng(options.seed ^ kVplPhotonSeed, 1);
  const std::array<float, 2> shift{shift_rng.uniform(), shift_rng.uniform()};
  return {trace_paths(tracer, total, options.seed ^ kVplPhotonSeed, options.max_vertices, threads,
                      [&](std::size_t i, Pcg32& rng) -> std::optional<PhotonSource> {
                        const auto [index, probability] =
                            sources.pick((static_cast<double>(i) + rng.uniform()) / static_cast<double>(total));
                        const Vpl& vpl = vpls[index];
                        const auto [u1, u2] = rotated_halton(static_cast<std::uint32_t>(i), shift);
                        const auto [direction, pdf] = detail::sample_cone_towards(vpl.position, target, u1, u2);
                        const float cos_y = direction.dot(vpl.normal);
                        if (cos_y <= 0.f || direction.dot(vpl.geometric_normal) <= 0.f || !(pdf > 0.f))
                          return std::nullopt;
                        const Vec3 f = phong_brdf(vpl_phong(scene, vpl), vpl.normal, vpl.incident, direction);
                        const float scale =
                            cos_y / (pdf * static_cast<float>(probability * static_cast<double>(total)));
                        const float offset = 1e-4f * (1.f + vpl.position.cwiseAbs().maxCoeff());
                        return PhotonSource{
                            {vpl.position + offset * vpl.geometric_normal, direction, vpl.flux.cwiseProduct(f) * scale},
                            vpl.in_real_virtual,
                            vpl.in_real};
                      }),
          PhotonKernel{options.vpl_radius, options.vpl_radius, options.neighbours}, true};
}

void add_caustic_light(DifferentialImages& images, const GBuffer& gbuffer, const MrScene& scene,
                       const CausticPhotons& photons, const Eigen::Vector3f& camera_centre, const PositionMap* eyes,
                       const RadianceImage* weights, int threads) {
  if (photons.empty()) return;
  const RadianceImage kd_texture = texture_factors(gbuffer, scene, MaterialTexture::BaseColor);
  const RadianceImage metallic_roughness = texture_factors(gbuffer, scene, MaterialTexture::MetallicRoughness);
  const int width = gbuffer.distance.width();
  const bool indirect = photons.indirect() && images.indirect_real_virtual.same_shape(images.real_virtual) &&
                        images.indirect_real.same_shape(images.real);
  const auto vec = [](const Float3& f) { return Vec3(f.x, f.y, f.z); };
  parallel_rows(
      gbuffer.distance.height(), threads,
      [&](int begin, int end) {
        for (int y = begin; y < end; ++y)
          for (int x = 0; x < width; ++x) {
            if (gbuffer.distance(y, x) == 0.f) continue;
            const Float3 w = weights ? (*weights)(y, x) : Float3{1.f, 1.f, 1.f};
            if (w == Float3{}) continue;
            const PhongMaterial& material = scene.materials[gbuffer.material(y, x) - 1u];
            const Phong phong = with_kd_factor(surface_phong(material, texture_factor_at(metallic_roughness, x, y)),
                                               texture_factor_at(kd_texture, x, y));
            const Vec3 p = vec(gbuffer.position(y, x)), n = vec(gbuffer.normal(y, x));
            const Vec3 wo = ((eyes ? vec((*eyes)(y, x)) : camera_centre) - p).normalized();
            const bool real_surface = !gbuffer.virtual_surface(y, x);
            Vec3 rv = Vec3::Zero(), real = Vec3::Zero();
            photons.for_each_near(p, [&](const CausticPhoton& q) {
              // On this side of this surface: not through a thin wall, not from a surface at an angle.
              const float r = q.radius;
              if (q.normal.dot(n) < 0.7f || std::abs((q.position - p).dot(n)) > 0.5f * r || q.incident.dot(n) <= 0.f)
                return;
              const float falloff = 3.f / (std::numbers::pi_v<float> * r * r) * (1.f - (q.position - p).norm() / r);
              const Vec3 light = phong_brdf(phong, n, q.incident, wo).cwiseProduct(q.flux) * falloff;
              if (q.real_world) {
                if (real_surface) real += light;
              } else {
                rv += light;
              }
            });
            const Vec3 scale = vec(w);
            const Float3 add_rv{rv.x() * scale.x(), rv.y() * scale.y(), rv.z() * scale.z()};
            const Float3 add_real{real.x() * scale.x(), real.y() * scale.y(), real.z() * scale.z()};
            images.real_virtual(y, x) += add_rv;
            images.real(y, x) += add_real;
            if (indirect) {
              images.indirect_real_virtual(y, x) += add_rv;
              images.indirect_real(y, x) += add_real;
            }
          }
      },
      4);
}

}  // namespace relight::render
