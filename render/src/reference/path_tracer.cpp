#include "relight/render/reference/path_tracer.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include "reference/caustic_light_tracer.h"
#include "relight/core/error.h"
#include "relight/core/parallel.h"
#include "relight/render/scene/phong_brdf.h"
#include "relight/render/scene/sampler.h"
#include "relight/render/scene/specular_bsdf.h"
#include "scene/surface_shading.h"

namespace relight::render {
namespace {

using namespace detail;

/// Where a camera path stands: its non-specular bounces (the bounce limit and Russian roulette
/// count these), its specular ones (capped separately, so that light crossing a glass object or
/// bouncing inside it is not cut by the diffuse bounce limit) and the dielectric it is inside.
struct PathState {
  int bounces = 0;
  int specular_bounces = 0;
  const SpecularMaterial* medium = nullptr;
};

class PathIntegrator {
 public:
  PathIntegrator(const MrScene& scene, const RayTracer& tracer, const PathTracerOptions& options)
      : scene_(scene), tracer_(tracer), options_(options) {}

  /// The joint L_rv / L_r estimate of one camera ray.
  DifferentialPathTracer::Sample trace(Vec3 origin, Vec3 direction, Pcg32& rng) const;

 private:
  /// Adds the radiance along one ray in one version of the scene (with or without the virtual
  /// objects), weighted by `throughput`, to `radiance`. It repeats the joint path's arithmetic
  /// exactly, so L_r does not change by a bit when virtual objects are added to a scene.
  void trace_layer(Vec3 origin, Vec3 direction, PathState state, bool with_virtual, Vec3 throughput, Vec3& radiance,
                   Pcg32& rng, std::uint32_t& rays) const;
  /// Next-event estimation at v, shared by both versions of the scene: for every light (the
  /// virtual ones only when `virtual_lights`) whose sample is lit and not blocked by real
  /// geometry, add(light, f cos E, virtual_visible), where virtual_visible says whether no
  /// virtual geometry blocks it either (tested only when `test_virtual`, else true). Nothing at
  /// a specular vertex: its delta directions never point at a light (caustic_light_tracer.h
  /// brings the light that reaches surfaces through them).
  template <class Add>
  void direct_lights(const Vertex& v, bool virtual_lights, bool test_virtual, std::uint32_t& rays, Add&& add) const;
  /// Samples the continuation; false when the path ends (bounce limit, absorption, roulette).
  bool continue_path(const Vertex& v, PathState& state, Vec3& throughput, Vec3& origin, Vec3& direction,
                     Pcg32& rng) const;

  const MrScene& scene_;
  const RayTracer& tracer_;
  const PathTracerOptions& options_;
};

bool PathIntegrator::continue_path(const Vertex& v, PathState& state, Vec3& throughput, Vec3& origin, Vec3& direction,
                                   Pcg32& rng) const {
  if (v.specular) {
    if (state.specular_bounces >= options_.max_specular_bounces) return false;
    const std::optional<SpecularSample> sample =
        sample_specular(*v.specular, v.outward, v.wo, rng.uniform(), Transport::Radiance);
    if (!sample) return false;
    throughput = throughput.cwiseProduct(sample->weight);
    if (sample->transmitted) state.medium = v.outward.dot(v.wo) >= 0.f ? v.specular : nullptr;
    ++state.specular_bounces;
    origin = offset_origin(v, sample->wi);
    direction = sample->wi;
    return true;
  }
  if (state.bounces >= options_.max_bounces) return false;
  const float u1 = rng.uniform();
  const float u2 = rng.uniform();
  const std::optional<BrdfSample> sample = sample_phong(v.brdf, v.shading_normal, v.wo, u1, u2);
  if (!sample || sample->wi.dot(v.geometric_normal) <= 0.f) return false;
  throughput = throughput.cwiseProduct(sample->weight);
  if (state.bounces + 1 >= options_.roulette_from) {
    const float survive = std::min(0.95f, throughput.maxCoeff());
    if (!(rng.uniform() < survive)) return false;
    throughput /= survive;
  }
  ++state.bounces;
  origin = offset_origin(v, sample->wi);
  direction = sample->wi;
  return true;
}

template <class Add>
void PathIntegrator::direct_lights(const Vertex& v, bool virtual_lights, bool test_virtual, std::uint32_t& rays,
                                   Add&& add) const {
  if (v.specular) return;
  for (const MrLight& light : scene_.lights) {
    if (!virtual_lights && !light.real) continue;
    const std::optional<LightSample> sample = sample_light(light, v.point);
    if (!sample) continue;
    const Vec3 contribution = direct_light(v, *sample);
    if (contribution.isZero()) continue;
    const Vec3 from = offset_origin(v, sample->wi);
    const float reach = sample->distance * (1.f - 1e-4f);
    ++rays;
    if (tracer_.occluded(Layer::Real, from, sample->wi, reach)) continue;
    bool virtual_visible = true;
    if (test_virtual) {
      ++rays;
      virtual_visible = !tracer_.occluded(Layer::Virtual, from, sample->wi, reach);
    }
    add(light, contribution, virtual_visible);
  }
}

void PathIntegrator::trace_layer(Vec3 origin, Vec3 direction, PathState state, bool with_virtual, Vec3 throughput,
                                 Vec3& radiance, Pcg32& rng, std::uint32_t& rays) const {
  for (;;) {
    const std::optional<SurfaceHit> hit = nearest_hit(tracer_, origin, direction, with_virtual, rays);
    if (!hit) {
      radiance += throughput.cwiseProduct(scene_.environment.radiance);
      break;
    }
    if (state.medium) throughput = throughput.cwiseProduct(beer_lambert(*state.medium, hit->t));
    const Vertex v = make_vertex(*hit, direction, scene_);
    radiance += throughput.cwiseProduct(v.emission);
    direct_lights(v, with_virtual, with_virtual && tracer_.has_virtual_geometry(), rays,
                  [&](const MrLight&, const Vec3& contribution, bool virtual_visible) {
                    if (virtual_visible) radiance += throughput.cwiseProduct(contribution);
                  });
    if (!continue_path(v, state, throughput, origin, direction, rng)) break;
  }
}

DifferentialPathTracer::Sample PathIntegrator::trace(Vec3 origin, Vec3 direction, Pcg32& rng) const {
  DifferentialPathTracer::Sample out;
  const bool has_virtual = tracer_.has_virtual_geometry();
  Vec3 throughput = Vec3::Ones();
  PathState state;
  for (bool first = true;; first = false) {
    ++out.rays;
    const std::optional<SurfaceHit> hit = tracer_.intersect(Layer::Real, origin, direction);
    bool virtual_in_front = false;
    if (has_virtual) {
      ++out.rays;
      virtual_in_front = tracer_.occluded(Layer::Virtual, origin, direction,
                                          hit ? hit->t : std::numeric_limits<float>::infinity());
    }
    if (virtual_in_front) {
      // The two versions of the scene differ from here on: finish each path on its own, both
      // continuing the same random stream.
      out.virtual_first_hit = first;
      Pcg32 rng_real = rng;
      trace_layer(origin, direction, state, true, throughput, out.real_virtual, rng, out.rays);
      trace_layer(origin, direction, state, false, throughput, out.real, rng_real, out.rays);
      break;
    }
    if (!hit) {
      const Vec3 sky = throughput.cwiseProduct(scene_.environment.radiance);
      out.real_virtual += sky;
      out.real += sky;
      break;
    }
    if (state.medium) throughput = throughput.cwiseProduct(beer_lambert(*state.medium, hit->t));
    const Vertex v = make_vertex(*hit, direction, scene_);
    const Vec3 emitted = throughput.cwiseProduct(v.emission);
    out.real_virtual += emitted;
    out.real += emitted;
    direct_lights(v, true, has_virtual, out.rays,
                  [&](const MrLight& light, const Vec3& contribution, bool virtual_visible) {
                    const Vec3 weighted = throughput.cwiseProduct(contribution);
                    if (light.real) out.real += weighted;
                    if (virtual_visible) out.real_virtual += weighted;
                  });
    if (!continue_path(v, state, throughput, origin, direction, rng)) break;
  }
  return out;
}

}  // namespace

DifferentialPathTracer::DifferentialPathTracer(const MrScene& scene, PathTracerOptions options)
    : options_(options), tracer_(scene) {
  if (options_.max_bounces < 0) throw Error("max bounces must not be negative");
  if (options_.max_specular_bounces < 0) throw Error("max specular bounces must not be negative");
  if (options_.roulette_from < 1) throw Error("Russian roulette must start at bounce 1 or later");
  if (!(options_.caustic_paths_per_pixel >= 0.0) || !std::isfinite(options_.caustic_paths_per_pixel))
    throw Error("caustic paths per pixel must be a number of at least 0");
  caustics_ = std::make_unique<detail::CausticLightTracer>(tracer_, options_);
}

DifferentialPathTracer::~DifferentialPathTracer() = default;

void DifferentialPathTracer::reset(const MrCamera& camera) {
  if (camera.intrinsics.width <= 0 || camera.intrinsics.height <= 0) throw Error("the render size must be positive");
  camera_ = camera;
  const auto pixels = static_cast<std::size_t>(camera.intrinsics.width) * static_cast<std::size_t>(camera.intrinsics.height);
  sum_rv_.assign(3 * pixels, 0.0);
  sum_r_.assign(3 * pixels, 0.0);
  virtual_hits_.assign(pixels, 0);
  samples_done_ = 0;
  rays_ = 0;
  light_paths_ = 0;
}

DifferentialPathTracer::Sample DifferentialPathTracer::trace_pixel(double u, double v, std::uint64_t pixel,
                                                                   std::uint64_t sample) const {
  Pcg32 rng = Pcg32::for_sample(options_.seed, pixel, sample);
  const double jitter_u = u + rng.uniform() - 0.5;
  const double jitter_v = v + rng.uniform() - 0.5;
  const PinholeIntrinsics& k = camera_.intrinsics;
  const Eigen::Vector3d camera_direction((jitter_u - k.cx) / k.fx, (jitter_v - k.cy) / k.fy, 1.0);
  const Vec3 direction = (camera_.camera_to_world.linear() * camera_direction.normalized()).cast<float>();
  const Vec3 origin = camera_.camera_to_world.translation().cast<float>();
  const PathIntegrator integrator(tracer_.scene(), tracer_, options_);
  Sample out = integrator.trace(origin, direction.normalized(), rng);
  if (!out.real_virtual.allFinite() || !out.real.allFinite()) {
    out.real_virtual.setZero();
    out.real.setZero();
  }
  return out;
}

void DifferentialPathTracer::add_samples(int samples) {
  if (sum_rv_.empty()) throw LogicError("DifferentialPathTracer::reset must come before add_samples");
  if (samples <= 0) return;
  std::atomic<std::uint64_t> rays{0};
  const int width = camera_.intrinsics.width;
  const auto first = static_cast<std::uint64_t>(samples_done_);
  parallel_rows(camera_.intrinsics.height, options_.threads, [&](int begin, int end) {
    std::uint64_t local_rays = 0;
    for (int row = begin; row < end; ++row)
      for (int col = 0; col < width; ++col) {
        const auto pixel = static_cast<std::size_t>(row) * static_cast<std::size_t>(width) + static_cast<std::size_t>(col);
        for (int s = 0; s < samples; ++s) {
          const Sample sample = trace_pixel(col, row, pixel, first + static_cast<std::uint64_t>(s));
          for (int c = 0; c < 3; ++c) {
            sum_rv_[3 * pixel + static_cast<std::size_t>(c)] += sample.real_virtual[c];
            sum_r_[3 * pixel + static_cast<std::size_t>(c)] += sample.real[c];
          }
          virtual_hits_[pixel] += sample.virtual_first_hit ? 1u : 0u;
          local_rays += sample.rays;
        }
      }
    rays += local_rays;
  }, 1);
  if (caustics_->active() && options_.caustic_paths_per_pixel > 0.0) {
    const auto paths = static_cast<std::uint64_t>(std::max(
        1.0, std::round(options_.caustic_paths_per_pixel * camera_.intrinsics.width * camera_.intrinsics.height)));
    for (int s = 0; s < samples; ++s)
      rays += caustics_->trace(camera_, paths, first + static_cast<std::uint64_t>(s), sum_rv_, sum_r_);
    light_paths_ += paths * tracer_.scene().lights.size() * static_cast<std::uint64_t>(samples);
  }
  samples_done_ += samples;
  rays_ += rays.load();
}

void DifferentialPathTracer::render(int samples_per_pixel, std::chrono::duration<double> budget,
                                    const RenderProgress& progress) {
  const auto start = std::chrono::steady_clock::now();
  while (samples_done_ < samples_per_pixel) {
    add_samples(1);
    if (progress) progress(samples_done_, samples_per_pixel);
    if (budget.count() > 0 && std::chrono::steady_clock::now() - start >= budget) break;
  }
}

DifferentialImages DifferentialPathTracer::images() const {
  DifferentialImages out;
  out.real_virtual = RadianceImage(camera_.intrinsics.width, camera_.intrinsics.height);
  out.real = RadianceImage(camera_.intrinsics.width, camera_.intrinsics.height);
  out.virtual_coverage = CoverageImage(camera_.intrinsics.width, camera_.intrinsics.height);
  out.samples_per_pixel = samples_done_;
  if (samples_done_ == 0) return out;
  const double scale = 1.0 / samples_done_;
  for (int row = 0; row < camera_.intrinsics.height; ++row)
    for (int col = 0; col < camera_.intrinsics.width; ++col) {
      const auto pixel = static_cast<std::size_t>(row) * static_cast<std::size_t>(camera_.intrinsics.width) + static_cast<std::size_t>(col);
      const auto average = [&](const std::vector<double>& sum) {
        return Float3{static_cast<float>(sum[3 * pixel] * scale), static_cast<float>(sum[3 * pixel + 1] * scale),
                      static_cast<float>(sum[3 * pixel + 2] * scale)};
      };
      out.real_virtual(row, col) = average(sum_rv_);
      out.real(row, col) = average(sum_r_);
      out.virtual_coverage(row, col) = static_cast<float>(virtual_hits_[pixel] * scale);
    }
  return out;
}

DifferentialImages render_reference(const MrScene& scene, const MrCamera& camera, int samples_per_pixel,
                                    const PathTracerOptions& options) {
  DifferentialPathTracer tracer(scene, options);
  tracer.reset(camera);
  tracer.add_samples(samples_per_pixel);
  return tracer.images();
}

}  // namespace relight::render
