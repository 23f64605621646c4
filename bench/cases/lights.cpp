// Light extraction from the synthetic scene's 512x512 fisheye probe: importance sampling (CPU and
// Vulkan, 64 and 256 VPLs; goal <= 1 ms per frame on the CPU) and median cut. The probe geometry
// (per-pixel solid angle) is built once per sequence, so it is outside the timing.
#include "bench.h"
#include "relight/lights/importance_sampling.h"
#include "relight/lights/median_cut.h"
#include "relight/synth/probe.h"
#include "relight/vk/context.h"

namespace {

using namespace relight;

struct Probe {
  RadianceImage image;
  lights::ProbeGeometry geometry;
};

const Probe& probe_512() {
  static const Probe probe = [] {
    const synth::Scene scene = synth::default_indoor_scene();
    const synth::LightProbe light_probe = synth::default_probe(scene);
    Probe p;
    p.image = synth::render_probe(scene, light_probe);
    lights::ProbeCalibration calibration;
    calibration.fisheye = light_probe.camera;
    p.geometry = lights::ProbeGeometry(calibration, p.image.width(), p.image.height());
    return p;
  }();
  return probe;
}

bench::Json importance_cpu(const bench::Options& options) {
  const Probe& p = probe_512();
  lights::ImportancePyramid pyramid;
  auto time = [&](int n) {
    return bench::median_ms(
        [&] {
          (void)lights::sample_importance(p.image, p.geometry, {n, 0}, pyramid);
        },
        options.repetitions);
  };
  return {{"ms", time(64)}, {"n_lights", 64}, {"ms_256", time(256)}, {"width", 512}, {"height", 512}};
}

bench::Json importance_vulkan(const bench::Options& options) {
  auto context = vk::try_create_vulkan();
  if (!context) return {{"skipped", "no Vulkan device"}};
  const Probe& p = probe_512();
  lights::ImportanceSamplerVk sampler(*context, p.geometry);
  auto time = [&](int n) {
    return bench::median_ms([&] { (void)sampler.run(p.image, {n, 0}); }, options.repetitions);
  };
  const double ms = time(64);
  const double gpu_ms = sampler.last_gpu_ms().value_or(-1.0);
  return {{"ms", ms},       {"n_lights", 64}, {"gpu_ms", gpu_ms}, {"ms_256", time(256)},
          {"device", context->device_info().name}, {"unit", "ms per frame incl. upload and download"}};
}

bench::Json median_cut_cpu(const bench::Options& options) {
  const Probe& p = probe_512();
  const double ms = bench::median_ms([&] { (void)lights::median_cut(p.image, p.geometry, {64}); }, options.repetitions);
  return {{"ms", ms}, {"n_lights", 64}, {"width", 512}, {"height", 512}};
}

RELIGHT_BENCH_CASE("lights/importance_cpu", importance_cpu);
RELIGHT_BENCH_CASE("lights/importance_vulkan", importance_vulkan);
RELIGHT_BENCH_CASE("lights/median_cut_cpu", median_cut_cpu);

}  // namespace
