#pragma once
// The differential path tracer: the CPU ground truth that the DIR renderer is measured against
// (Knecht's dissertation §5.2.13; differential path tracing as in Kán & Kaufmann 2012/2013).
//
// Reads an MrScene and an MrCamera; writes per pixel
//   L_rv  radiance of the whole scene (real + virtual meshes and lights),
//   L_r   radiance of the real scene alone (virtual meshes invisible to every ray, virtual
//         lights off),
//   the fraction of camera samples whose first hit is a virtual object (the composite's mask).
//
// Both estimates come from the same camera path: while the path only meets real surfaces and
// its shadow rays are not blocked by virtual ones, L_r and L_rv share every sample, so their
// difference is exactly zero wherever virtual objects change nothing and has low variance
// elsewhere. At the first vertex where the paths differ (a virtual hit) the path splits into an
// L_rv and an L_r continuation that keep using the same random numbers.
//
// Estimator per path vertex x_k (k = 0 the camera hit): emitted radiance, next-event estimation
// towards every point, spot and directional light (one shadow ray each), and - while
// k < max_bounces - a continuation by Phong importance sampling (phong_brdf.h) with Russian
// roulette from bounce `roulette_from` on. Rays that leave the scene gather the environment.
// Surface emission is only found by BRDF sampling (no area-light sampling), which keeps the
// estimator simple and unbiased; it is efficient for the point-like lights of our scenes.
//
// Mirrors, metals and glass (specular_material.h) are delta scatterers: a camera path follows
// them by sampling reflection or refraction in proportion to Fresnel (specular_bsdf.h; these
// vertices count against max_specular_bounces, not max_bounces) and attenuates by Beer-Lambert
// inside glass; they get no next-event estimate. The light those surfaces focus onto others
// (caustics) comes from light paths splatted to the camera (caustic_paths_per_pixel per pixel
// and pass, src/reference/caustic_light_tracer.h), which take exactly the paths camera paths
// cannot, so the sum counts nothing twice. A scene without specular materials traces no light
// path and renders as before.
//
// Deterministic: every sample of every pixel has its own random stream (sampler.h), so the
// result depends on the seed and the sample count only, not on threads or pass sizes.
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "relight/core/image.h"
#include "relight/render/differential_images.h"
#include "relight/render/scene/mr_scene.h"
#include "relight/render/reference/ray_tracer.h"

namespace relight::render {

namespace detail {
class CausticLightTracer;
}

struct PathTracerOptions {
  int max_bounces = 4;    ///< indirect bounces after the camera hit (0 = direct light only)
  int roulette_from = 3;  ///< first bounce at which Russian roulette may end a path
  int max_specular_bounces = 16;  ///< reflections and refractions at specular surfaces per path
  /// Caustic light paths per light, per pixel of the image and per pass (0 = none: the light
  /// focused by mirrors and glass is then missing).
  double caustic_paths_per_pixel = 1.0;
  std::uint64_t seed = 1;
  int threads = 0;  ///< 0 = all hardware threads
};

/// Called after each progressive pass with (samples done, samples wanted).
using RenderProgress = std::function<void(int, int)>;

class DifferentialPathTracer {
 public:
  DifferentialPathTracer(const MrScene& scene, PathTracerOptions options = {});
  ~DifferentialPathTracer();
  DifferentialPathTracer(const DifferentialPathTracer&) = delete;
  DifferentialPathTracer& operator=(const DifferentialPathTracer&) = delete;

  /// Starts a new image for `camera` (drops the accumulated samples).
  void reset(const MrCamera& camera);
  /// Adds `samples` samples to every pixel.
  void add_samples(int samples);
  /// Adds samples until `samples_per_pixel` are done or `budget` has passed (checked between
  /// passes of one sample each; zero = no time limit).
  void render(int samples_per_pixel, std::chrono::duration<double> budget = {}, const RenderProgress& progress = {});

  [[nodiscard]] int samples_done() const { return samples_done_; }
  /// Rays traced since reset: camera, continuation and shadow rays, each layer query counted.
  [[nodiscard]] std::uint64_t rays_traced() const { return rays_; }
  /// Caustic light paths traced since reset (zero in a scene without specular materials).
  [[nodiscard]] std::uint64_t light_paths_traced() const { return light_paths_; }
  /// The current averages.
  [[nodiscard]] DifferentialImages images() const;

  /// One camera sample through the continuous image position (u, v) - exposed for tests (the
  /// camera paths alone, without the caustic light paths).
  struct Sample {
    Eigen::Vector3f real_virtual = Eigen::Vector3f::Zero();
    Eigen::Vector3f real = Eigen::Vector3f::Zero();
    bool virtual_first_hit = false;
    std::uint32_t rays = 0;
  };
  [[nodiscard]] Sample trace_pixel(double u, double v, std::uint64_t pixel, std::uint64_t sample) const;

 private:
  PathTracerOptions options_;
  RayTracer tracer_;  // holds the scene
  std::unique_ptr<detail::CausticLightTracer> caustics_;  // refers to tracer_ and options_
  MrCamera camera_;
  std::vector<double> sum_rv_, sum_r_;
  std::vector<std::uint32_t> virtual_hits_;
  int samples_done_ = 0;
  std::uint64_t rays_ = 0;
  std::uint64_t light_paths_ = 0;
};

/// Renders `samples_per_pixel` samples of `camera` in one call.
[[nodiscard]] DifferentialImages render_reference(const MrScene& scene, const MrCamera& camera, int samples_per_pixel,
                                                  const PathTracerOptions& options = {});

}  // namespace relight::render
