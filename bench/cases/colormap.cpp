// colormap/*: camera-adaptive colour mapping per 640x480 frame on the synthetic camera
// (synthetic_camera.h: white balance, crosstalk, exposure, gamma), orange virtual sphere.
// "ms" is one frame of the mapping stage's work (statistics/fit + delta_L); the quality fields
// are the mean CIEDE2000 over the virtual object before (no mapping) and after, against the
// object as the true camera shows it. Goal: stats_cpu <= 2 ms.
#include <algorithm>
#include <string>
#include <vector>

#include "bench.h"
#include "vulkan_timing.h"
#include "relight/colormap/sample_mapping.h"
#include "relight/colormap/statistics_transfer.h"
#include "relight/colormap/statistics_transfer_vk.h"
#include "relight/truth/synthetic_camera.h"
#include "relight/vk/backend.h"
#include "relight/vk/buffer.h"
#include "relight/vk/context.h"
#include "relight/vk/transfer.h"

namespace {

using namespace relight;
using namespace relight::colormap;

const truth::SyntheticTriple& frame_640x480() {
  static const truth::SyntheticTriple triple = truth::make_synthetic_triple({.width = 640, .height = 480});
  return triple;
}

double delta_e_of(const truth::SyntheticTriple& triple, const RadianceImage& delta) {
  return truth::mean_delta_e(composite(triple.camera, delta), triple.truth, virtual_mask(triple.real, triple.real_virtual));
}

double delta_e_before(const truth::SyntheticTriple& triple) {
  RadianceImage identity;
  sample_delta(triple.real, triple.real_virtual, identity_color_matrix(), {}, identity);
  return delta_e_of(triple, identity);
}

bench::Json stats_cpu(const bench::Options& options) {
  const truth::SyntheticTriple& triple = frame_640x480();
  RadianceImage delta;
  const double ms = bench::median_ms(
      [&] { (void)statistics_color_map(triple.real, triple.real_virtual, triple.camera, {}, delta); },
      options.repetitions);
  const double statistics_ms = bench::median_ms(
      [&] { (void)masked_lab_statistics(triple.real, triple.real_virtual, triple.camera, {}); }, options.repetitions);
  return {{"ms", ms}, {"statistics_ms", statistics_ms}, {"delta_e_before", delta_e_before(triple)},
          {"delta_e_after", delta_e_of(triple, delta)}, {"width", 640}, {"height", 480}};
}

bench::Json sample_cpu(const bench::Options& options) {
  const truth::SyntheticTriple& triple = frame_640x480();
  RadianceImage delta;
  bench::Json json;
  for (const auto model : {PolynomialModel::PerChannelAffine, PolynomialModel::Linear3x3, PolynomialModel::Affine3x4}) {
    SampleColorMapper mapper({.model = model});
    const double ms =
        bench::median_ms([&] { (void)mapper.map(triple.real, triple.real_virtual, triple.camera, delta); },
                         options.repetitions);
    if (model == PolynomialModel::Affine3x4) {  // the default model gives the headline fields
      json["ms"] = ms;
      json["model"] = to_string(model);
      json["delta_e_before"] = delta_e_before(triple);
      json["delta_e_after"] = delta_e_of(triple, delta);
    }
    json[std::string("delta_e_after_") + to_string(model)] = delta_e_of(triple, delta);
  }
  json["samples"] = 64;
  json["grid_step"] = 4;
  return json;
}

bench::Json stats_vulkan(const bench::Options& options) {
  const auto context = relight::bench::timing_vulkan();
  const truth::SyntheticTriple& triple = frame_640x480();
  StatisticsColorMapVk mapper(*context);
  vk::VulkanTransfer& transfer = context->transfer();
  vk::VulkanBuffer real(*context, triple.real.bytes().size()), real_virtual(*context, triple.real.bytes().size());
  vk::VulkanBuffer camera(*context, triple.camera.bytes().size()), delta(*context, triple.real.bytes().size());
  transfer.upload(triple.real.bytes(), real);
  transfer.upload(triple.real_virtual.bytes(), real_virtual);
  transfer.upload(triple.camera.bytes(), camera);
  std::vector<double> gpu_ms;
  const double ms = bench::median_ms(
      [&] {
        (void)mapper.run(real, real_virtual, camera, delta, 640, 480);
        if (const auto t = mapper.last_gpu_ms()) gpu_ms.push_back(*t);
      },
      options.repetitions);
  RadianceImage host_delta(640, 480);
  transfer.download(delta, host_delta.bytes());
  std::sort(gpu_ms.begin(), gpu_ms.end());
  return {{"ms", ms},
          {"gpu_ms", gpu_ms.empty() ? -1.0 : gpu_ms[gpu_ms.size() / 2]},
          {"delta_e_before", delta_e_before(triple)},
          {"delta_e_after", delta_e_of(triple, host_delta)},
          {"device", context->device_info().name},
          {"auto_backend", to_string(vk::choose_backend(vk::StageKind::PerPixel, context.get()))}};
}

}  // namespace

RELIGHT_BENCH_CASE("colormap/stats_cpu", stats_cpu);
RELIGHT_BENCH_CASE("colormap/sample_cpu", sample_cpu);
RELIGHT_BENCH_CASE("colormap/stats_vulkan", stats_vulkan);
