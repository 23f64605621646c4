#include "reference/caustic_light_tracer.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "relight/core/parallel.h"
#include "relight/render/scene/phong_brdf.h"
#include "relight/render/scene/sampler.h"
#include "relight/render/scene/specular_bsdf.h"
#include "scene/caustic_emission.h"
#include "scene/surface_shading.h"

namespace relight::render::detail {
namespace {

/// Light paths per parallel work item: their splats are merged in this order, so the sums do not
/// depend on the threads.
constexpr std::uint64_t kPathsPerChunk = 2048;
/// Mixed into the seed so that light paths draw other numbers than the camera paths.
constexpr std::uint64_t kLightPathSeed = 0x6c1a5c9e3b7d2f41ull;

struct Splat {
  std::uint32_t pixel = 0;
  bool real_virtual = true;  ///< L_rv, else L_r
  Vec3 value;
};

/// One light path in one version of the scene (see the header).
class LightPathWalker {
 public:
  LightPathWalker(const RayTracer& tracer, const PathTracerOptions& options, const MrCamera& camera, float inv_paths)
      : tracer_(tracer), options_(options), camera_(camera), inv_paths_(inv_paths) {}

  void walk(const Emission& emission, bool with_virtual, Pcg32 rng, std::vector<Splat>& out,
            std::uint64_t& rays) const {
    std::uint32_t counted = 0;
    Vec3 origin = emission.origin, direction = emission.direction, beta = emission.beta;
    const SpecularMaterial* medium = nullptr;
    int bounces = 0, specular_bounces = 0;
    for (bool first = true;; first = false) {
      const std::optional<SurfaceHit> hit = nearest_hit(tracer_, origin, direction, with_virtual, counted);
      if (!hit) break;
      if (medium) beta = beta.cwiseProduct(beer_lambert(*medium, hit->t));
      const Vertex v = make_vertex(*hit, direction, tracer_.scene());
      if (v.specular) {
        if (specular_bounces >= options_.max_specular_bounces) break;
        const std::optional<SpecularSample> sample =
            sample_specular(*v.specular, v.outward, v.wo, rng.uniform(), Transport::Importance);
        if (!sample) break;
        beta = beta.cwiseProduct(sample->weight);
        if (sample->transmitted) medium = v.outward.dot(v.wo) >= 0.f ? v.specular : nullptr;
        ++specular_bounces;
        origin = offset_origin(v, sample->wi);
        direction = sample->wi;
        continue;
      }
      if (first) break;  // a non-specular vertex next to the light: the camera paths' share
      connect(v, beta, with_virtual, out, counted);
      if (bounces >= options_.max_bounces) break;
      const float u1 = rng.uniform();
      const float u2 = rng.uniform();
      // The modified Phong model is symmetric, so sampling it from the light's side gives the
      // flux weight f cos / pdf of the next direction.
      const std::optional<BrdfSample> sample = sample_phong(v.brdf, v.shading_normal, v.wo, u1, u2);
      if (!sample || sample->wi.dot(v.geometric_normal) <= 0.f) break;
      beta = beta.cwiseProduct(sample->weight);
      if (bounces + 1 >= options_.roulette_from) {
        const float survive = std::min(0.95f, beta.maxCoeff() / std::max(1e-30f, emission.beta.maxCoeff()));
        if (!(rng.uniform() < survive)) break;
        beta /= survive;
      }
      ++bounces;
      origin = offset_origin(v, sample->wi);
      direction = sample->wi;
    }
    rays += counted;
  }

 private:
  /// Splats the light leaving v towards the camera into the pixel v projects to, if the camera
  /// sees v in this version of the scene.
  void connect(const Vertex& v, const Vec3& beta, bool with_virtual, std::vector<Splat>& out,
               std::uint32_t& rays) const {
    const Vec3 eye = camera_.camera_to_world.translation().cast<float>();
    const Vec3 to_eye = eye - v.point;
    const float distance2 = to_eye.squaredNorm();
    if (!(distance2 > 0.f)) return;
    const float distance = std::sqrt(distance2);
    const Vec3 wc = to_eye / distance;
    if (wc.dot(v.geometric_normal) <= 0.f) return;
    const float cos_surface = wc.dot(v.shading_normal);
    if (cos_surface <= 0.f) return;
    const Vec3 local = (camera_.camera_to_world.linear().transpose().cast<float>()) * (v.point - eye);
    if (local.z() <= 0.f) return;
    const PinholeIntrinsics& k = camera_.intrinsics;
    const double u = k.fx * local.x() / local.z() + k.cx, w = k.fy * local.y() / local.z() + k.cy;
    const double col = std::floor(u + 0.5), row = std::floor(w + 0.5);
    if (col < 0 || row < 0 || col >= k.width || row >= k.height) return;
    const float cos_camera = local.z() / distance;
    const float importance = static_cast<float>(k.fx * k.fy) / (cos_camera * cos_camera * cos_camera);
    const Vec3 value = beta.cwiseProduct(phong_brdf(v.brdf, v.shading_normal, v.wo, wc)) *
                       (cos_surface / distance2 * importance * inv_paths_);
    if (!value.allFinite() || value.isZero()) return;
    const Vec3 from = offset_origin(v, wc);
    const float reach = distance * (1.f - 1e-4f);
    ++rays;
    if (tracer_.occluded(Layer::Real, from, wc, reach)) return;
    if (with_virtual && tracer_.has_virtual_geometry()) {
      ++rays;
      if (tracer_.occluded(Layer::Virtual, from, wc, reach)) return;
    }
    const auto pixel =
        static_cast<std::uint32_t>(row) * static_cast<std::uint32_t>(k.width) + static_cast<std::uint32_t>(col);
    out.push_back({pixel, with_virtual, value});
  }

  const RayTracer& tracer_;
  const PathTracerOptions& options_;
  const MrCamera& camera_;
  float inv_paths_;
};

}  // namespace

CausticLightTracer::CausticLightTracer(const RayTracer& tracer, const PathTracerOptions& options)
    : tracer_(tracer), options_(options) {
  const MrScene& scene = tracer.scene();
  specular_bounds_ = bounding_sphere(scene, SceneMeshes::Specular);
  scene_bounds_ = bounding_sphere(scene, SceneMeshes::All);
  active_ = specular_bounds_.radius > 0.f && !scene.lights.empty();
}

std::uint64_t CausticLightTracer::trace(const MrCamera& camera, std::uint64_t paths, std::uint64_t pass,
                                        std::vector<double>& sum_rv, std::vector<double>& sum_r) const {
  if (!active_ || paths == 0) return 0;
  const std::vector<MrLight>& lights = tracer_.scene().lights;
  const std::uint64_t total = paths * lights.size();
  const auto chunks = static_cast<int>((total + kPathsPerChunk - 1) / kPathsPerChunk);
  std::vector<std::vector<Splat>> splats(static_cast<std::size_t>(chunks));
  std::vector<std::uint64_t> rays(static_cast<std::size_t>(chunks), 0);
  const LightPathWalker walker(tracer_, options_, camera, 1.f / static_cast<float>(paths));
  parallel_rows(
      chunks, options_.threads,
      [&](int begin, int end) {
        for (int chunk = begin; chunk < end; ++chunk) {
          const auto c = static_cast<std::size_t>(chunk);
          const std::uint64_t first = c * kPathsPerChunk, last = std::min(total, first + kPathsPerChunk);
          for (std::uint64_t i = first; i < last; ++i) {
            const MrLight& light = lights[i / paths];
            Pcg32 rng = Pcg32::for_sample(options_.seed ^ kLightPathSeed, i, pass);
            const float u1 = rng.uniform();
            const float u2 = rng.uniform();
            const std::optional<Emission> emission = emit_towards(light, specular_bounds_, scene_bounds_, u1, u2);
            if (!emission) continue;
            walker.walk(*emission, true, rng, splats[c], rays[c]);
            if (light.real) walker.walk(*emission, false, rng, splats[c], rays[c]);
          }
        }
      },
      1);
  std::uint64_t traced = 0;
  for (std::size_t c = 0; c < splats.size(); ++c) {
    traced += rays[c];
    for (const Splat& splat : splats[c]) {
      std::vector<double>& sum = splat.real_virtual ? sum_rv : sum_r;
      for (int channel = 0; channel < 3; ++channel)
        sum[3 * std::size_t{splat.pixel} + static_cast<std::size_t>(channel)] += splat.value[channel];
    }
  }
  return traced;
}

}  // namespace relight::render::detail
