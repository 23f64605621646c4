// The differential path tracer (render/path_tracer.h) on the synthetic scene with the shipped
// glossy pebble on the table, seen from the first orbit pose.
//
// pt/reference_320x240: throughput (Mrays/s: camera, continuation and shadow rays, each layer
// query counted) and the time until the tone-mapped L_rv is within RMSE 0.05 of the converged
// image (and 0.02 for a finer goal). The error is estimated without a reference from two renders with independent seeds:
// for unbiased estimates E|A - B|^2 = 2 E|A - truth|^2, so RMSE(A) = RMSE(A - B) / sqrt(2).
// pt/convergence_80x60: RMSE against a 4096-spp render (independent seed) at 4..256 spp and the
// log-log slope (1/sqrt(spp) gives -0.5).
#include <chrono>
#include <cmath>

#include "bench.h"
#include "relight/render/scene/model_io.h"
#include "relight/render/reference/path_tracer.h"
#include "relight/render/scene/procedural_models.h"
#include "relight/truth/scene_from_synth.h"
#include "relight/synth/trajectory.h"

namespace {

using namespace relight;

render::MrScene scene_with_pebble() {
  const synth::Scene synthetic = synth::default_indoor_scene();
  render::MrScene scene = truth::scene_from_synth(synthetic);
  render::add_virtual_model(scene, render::make_glossy_pebble(), render::Placement::parse("0.35,-0.2,0.75,30"));
  return scene;
}

render::MrCamera camera(int width, int height) {
  const synth::Scene synthetic = synth::default_indoor_scene();
  const double s = width / 640.0;
  const Pose pose = synth::make_trajectory(synth::Trajectory::Orbit, 1, 0, synthetic).front();
  return {PinholeIntrinsics{525.0 * s, 525.0 * s, (width - 1) / 2.0, (height - 1) / 2.0, width, height}, pose};
}

/// RMSE between tone-mapped (clamped to [0, 1]) images.
double tone_mapped_rmse(const RadianceImage& a, const RadianceImage& b) {
  double sum = 0.0;
  const auto tm = [](float x) { return std::clamp(x, 0.f, 1.f); };
  for (std::size_t i = 0; i < a.size(); ++i) {
    const Float3 p = a.pixels()[i], q = b.pixels()[i];
    sum += std::pow(tm(p.x) - tm(q.x), 2) + std::pow(tm(p.y) - tm(q.y), 2) + std::pow(tm(p.z) - tm(q.z), 2);
  }
  return std::sqrt(sum / (3.0 * static_cast<double>(a.size())));
}

bench::Json reference_320x240(const bench::Options&) {
  const render::MrScene scene = scene_with_pebble();
  render::PathTracerOptions options_a, options_b;
  options_a.seed = 1;
  options_b.seed = 2;
  render::DifferentialPathTracer a(scene, options_a), b(scene, options_b);
  a.reset(camera(320, 240));
  b.reset(camera(320, 240));
  double seconds = 0.0;
  double ms_to_target = -1.0, ms_to_fine = -1.0;
  int spp_to_target = -1;
  double error = 1.0;
  bench::Json curve = bench::Json::array();
  for (int spp = 1; spp <= 128 && ms_to_fine < 0; spp *= 2) {
    const int more = spp - a.samples_done();
    const auto start = std::chrono::steady_clock::now();
    a.add_samples(more);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    b.add_samples(more);
    error = tone_mapped_rmse(a.images().real_virtual, b.images().real_virtual) / std::sqrt(2.0);
    curve.push_back({{"spp", spp}, {"rmse", error}, {"ms", 1e3 * seconds}});
    if (error <= 0.05 && ms_to_target < 0) {
      ms_to_target = 1e3 * seconds;
      spp_to_target = spp;
    }
    if (error <= 0.02) ms_to_fine = 1e3 * seconds;
  }
  const double mrays = static_cast<double>(a.rays_traced()) / 1e6 / seconds;
  return {{"ms", 1e3 * seconds / a.samples_done()},
          {"unit", "ms per sample per pixel (320x240)"},
          {"mrays_per_s", mrays},
          {"ms_to_rmse_0.05", ms_to_target < 0 ? bench::Json(nullptr) : bench::Json(ms_to_target)},
          {"spp_to_rmse_0.05", spp_to_target},
          {"ms_to_rmse_0.02", ms_to_fine < 0 ? bench::Json(nullptr) : bench::Json(ms_to_fine)},
          {"rmse_estimate", error},
          {"curve", curve},
          {"triangles", scene.triangle_count(true) + scene.triangle_count(false)}};
}

bench::Json convergence_80x60(const bench::Options&) {
  const render::MrScene scene = scene_with_pebble();
  render::PathTracerOptions reference_options;
  reference_options.seed = 99;
  const int reference_spp = 4096;
  const RadianceImage reference = render::render_reference(scene, camera(80, 60), reference_spp, reference_options).real_virtual;
  render::DifferentialPathTracer tracer(scene);
  tracer.reset(camera(80, 60));
  bench::Json curve = bench::Json::array();
  std::vector<double> x, y;
  for (int spp = 4; spp <= 256; spp *= 4) {
    tracer.add_samples(spp - tracer.samples_done());
    const double error = tone_mapped_rmse(tracer.images().real_virtual, reference);
    curve.push_back({{"spp", spp}, {"rmse", error}});
    x.push_back(std::log(spp));
    y.push_back(std::log(error));
  }
  // Least-squares slope of log(rmse) over log(spp).
  const double n = static_cast<double>(x.size());
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sx += x[i];
    sy += y[i];
    sxx += x[i] * x[i];
    sxy += x[i] * y[i];
  }
  const double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
  return {{"loglog_slope", slope}, {"reference_spp", reference_spp}, {"curve", curve}};
}

}  // namespace

RELIGHT_BENCH_CASE("pt/reference_320x240", reference_320x240);
RELIGHT_BENCH_CASE("pt/convergence_80x60", convergence_80x60);
