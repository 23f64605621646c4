// vpl/warp_cpu and vpl/warp_vulkan: hierarchical warping (render/hierarchical_warp.h) of 1024
// Hammersley points on a 512x512 importance map shaped like a spot light's reflective shadow map
// (a bright falloff disc with texture and an empty border). "ms" is the whole step a frame pays:
// the sum pyramid and the descent; pyramid_ms / descend_ms split it on the CPU, and the Vulkan
// case has the importance already on the device (it comes from the RSM pass) and reports the
// CPU as its baseline, the GPU timestamps (gpu_ms) and texel mismatches against the CPU.
// vpl/rsm_vulkan: the two rasterised RSMs (reflective_shadow_map_vk.h) of a real spot light over
// the synthetic room's table with the pebble on it, 256² texels, scene upload included (the
// reconstruction changes every frame), against the ray-cast reference (Embree on every core, its
// acceleration structure built beforehand), with the texels whose surface differs (coverage,
// material or world).
#include <algorithm>
#include <cmath>
#include <vector>

#include "bench.h"
#include "vulkan_timing.h"
#include "relight/render/vpl/hierarchical_warp.h"
#include "relight/render/vpl/hierarchical_warp_vk.h"
#include "relight/render/scene/procedural_models.h"
#include "relight/render/vpl/reflective_shadow_map_vk.h"
#include "relight/truth/scene_from_synth.h"
#include "relight/vk/buffer.h"
#include "relight/vk/context.h"
#include "relight/vk/transfer.h"

namespace {

using namespace relight::render;

constexpr int kSize = 512;
constexpr std::uint32_t kSamples = 1024;

std::vector<float> spot_like_map() {
  std::vector<float> map(static_cast<std::size_t>(kSize) * kSize, 0.f);
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const float dx = (static_cast<float>(x) - 256.f) / 200.f, dy = (static_cast<float>(y) - 256.f) / 200.f;
      const float r2 = dx * dx + dy * dy;
      if (r2 >= 1.f) continue;
      const float texture = 0.6f + 0.4f * std::sin(0.21f * static_cast<float>(x)) * std::cos(0.13f * static_cast<float>(y));
      map[static_cast<std::size_t>(y) * kSize + x] = (1.f - r2) * texture;
    }
  return map;
}

double median(std::vector<double> values) {
  if (values.empty()) return -1.0;
  std::sort(values.begin(), values.end());
  const std::size_t mid = values.size() / 2;
  return values.size() % 2 ? values[mid] : 0.5 * (values[mid - 1] + values[mid]);
}

relight::bench::Json warp_cpu(const relight::bench::Options& options) {
  const std::vector<float> map = spot_like_map();
  const std::vector<WarpPoint> points = hammersley_points(kSamples);
  std::vector<WarpedTexel> samples;
  const double ms = relight::bench::median_ms(
      [&] { samples = warp_points(ImportancePyramid(map, kSize), points); }, options.repetitions);
  const ImportancePyramid pyramid(map, kSize);
  const double pyramid_ms = relight::bench::median_ms([&] { (void)ImportancePyramid(map, kSize); }, options.repetitions);
  const double descend_ms =
      relight::bench::median_ms([&] { samples = warp_points(pyramid, points); }, options.repetitions);
  relight::bench::Json json;
  json["ms"] = ms;
  json["pyramid_ms"] = pyramid_ms;
  json["descend_ms"] = descend_ms;
  json["size"] = kSize;
  json["samples"] = kSamples;
  return json;
}

relight::bench::Json warp_vulkan(const relight::bench::Options& options) {
  namespace vk = relight::vk;
  const auto context = relight::bench::timing_vulkan();
  const std::vector<float> map = spot_like_map();
  const std::vector<WarpPoint> points = hammersley_points(kSamples);
  HierarchicalWarpVk warp(*context);
  vk::VulkanBuffer importance(*context, map.size() * sizeof(float));
  vk::VulkanBuffer point_buffer(*context, points.size() * sizeof(WarpPoint));
  vk::VulkanBuffer sample_buffer(*context, points.size() * sizeof(WarpedTexel));
  context->transfer().upload(std::as_bytes(std::span(map)), importance);
  context->transfer().upload(std::as_bytes(std::span(points)), point_buffer);

  std::vector<double> gpu_ms;
  const auto ours = [&] {
    if (const auto ms = warp.run(importance, kSize, point_buffer, kSamples, sample_buffer)) gpu_ms.push_back(*ms);
  };
  std::vector<WarpedTexel> cpu;
  const auto baseline = [&] { cpu = warp_points(ImportancePyramid(map, kSize), points); };
  const auto comparison = relight::bench::compare_interleaved(ours, baseline, options.repetitions);

  std::vector<WarpedTexel> gpu(kSamples);
  context->transfer().download(sample_buffer, std::as_writable_bytes(std::span(gpu)));
  int mismatches = 0;
  for (std::size_t i = 0; i < gpu.size(); ++i) mismatches += (gpu[i].x != cpu[i].x || gpu[i].y != cpu[i].y) ? 1 : 0;

  auto json = relight::bench::comparison_json(comparison, "warp_cpu");
  json["gpu_ms"] = median(gpu_ms);
  json["texel_mismatches"] = mismatches;
  json["size"] = kSize;
  json["samples"] = kSamples;
  json["device"] = context->device_info().name;
  return json;
}

MrScene room_with_spot() {
  MrScene scene = relight::truth::scene_from_synth(relight::synth::default_indoor_scene());
  add_virtual_model(scene, make_glossy_pebble(), Placement::parse("0.35,-0.2,0.75,30"));
  scene.lights = {spot_light({0.3f, -0.25f, 1.6f}, {0.05f, 0.05f, -1.f}, 30.f, 24.f, {4.f, 4.f, 4.f}, true)};
  return scene;
}

relight::bench::Json rsm_vulkan(const relight::bench::Options& options) {
  const auto context = relight::bench::timing_vulkan();
  constexpr int kRsmSize = 256;
  const MrScene scene = room_with_spot();
  const RayTracer tracer(scene);
  ReflectiveShadowMapsVk rasteriser(*context);
  std::vector<ReflectiveShadowMap> gpu, cpu;
  std::vector<double> gpu_ms;
  const auto ours = [&] {
    rasteriser.set_scene(scene);
    gpu = rasteriser.render(scene, 0, kRsmSize);
    gpu_ms.push_back(rasteriser.last_gpu_ms());
  };
  const auto baseline = [&] { cpu = reflective_shadow_maps_cpu(scene, tracer, 0, kRsmSize); };
  const auto comparison = relight::bench::compare_interleaved(ours, baseline, options.repetitions);
  int mismatches = 0;
  for (std::size_t m = 0; m < cpu.size(); ++m)
    for (std::size_t i = 0; i < cpu[m].texels.size(); ++i) {
      const auto &g = gpu[m].texels[i].hit, &c = cpu[m].texels[i].hit;
      const bool same = g.has_value() == c.has_value() &&
                        (!c || (g->material == c->material && g->real == c->real && (g->point - c->point).norm() < 0.005f));
      mismatches += same ? 0 : 1;
    }
  auto json = relight::bench::comparison_json(comparison, "rsm_ray_cast_cpu");
  json["gpu_ms"] = median(gpu_ms);
  json["texel_mismatches"] = mismatches;
  json["maps"] = cpu.size();
  json["size"] = kRsmSize;
  json["covered_real"] = cpu[0].covered();
  json["covered_virtual"] = cpu.size() > 1 ? cpu[1].covered() : 0;
  json["device"] = context->device_info().name;
  return json;
}

}  // namespace

RELIGHT_BENCH_CASE("vpl/warp_cpu", warp_cpu);
RELIGHT_BENCH_CASE("vpl/warp_vulkan", warp_vulkan);
RELIGHT_BENCH_CASE("vpl/rsm_vulkan", rsm_vulkan);
