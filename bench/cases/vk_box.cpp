// vk/box3x3_vs_cpu: the depth 3x3 box filter on Vulkan (ours) against the CPU reference
// (baseline) on a 640x480 synthetic depth with holes. "ms" is end to end (upload, dispatch, wait,
// download) because that is what a frame graph pays when a CPU stage follows; "dispatch_ms"
// (submit + wait, buffers already on the device) and "gpu_ms" (timestamp queries around the
// dispatch) show where the time goes. Validation is off so that it does not distort timings.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "bench.h"
#include "vulkan_timing.h"
#include "relight/reconstruct/depth_box_filter.h"
#include "relight/vk/backend.h"
#include "relight/vk/buffer.h"
#include "relight/vk/context.h"
#include "relight/vk/transfer.h"

namespace {

using relight::DepthMap;

DepthMap synthetic_depth(int width, int height) {
  DepthMap depth(width, height);
  std::mt19937 random(7);
  std::uniform_real_distribution<float> noise(-0.01f, 0.01f);
  std::uniform_int_distribution<int> percent(0, 99);
  for (int r = 0; r < height; ++r) {
    for (int c = 0; c < width; ++c) {
      const float surface =
          2.2f + 1.2f * std::sin(0.031f * static_cast<float>(c)) * std::cos(0.017f * static_cast<float>(r));
      depth(r, c) = percent(random) < 10 ? 0.f : surface + noise(random);  // 10 % holes
    }
  }
  return depth;
}

double median(std::vector<double> values) {
  if (values.empty()) return -1.0;
  std::sort(values.begin(), values.end());
  const std::size_t mid = values.size() / 2;
  return values.size() % 2 ? values[mid] : 0.5 * (values[mid - 1] + values[mid]);
}

relight::bench::Json box3x3_vs_cpu(const relight::bench::Options& options) {
  namespace vk = relight::vk;
  const auto context = relight::bench::timing_vulkan();

  constexpr int width = 640, height = 480;
  const DepthMap depth = synthetic_depth(width, height);
  relight::reconstruct::DepthBoxFilterVk filter(*context);
  vk::VulkanTransfer& transfer = context->transfer();
  vk::VulkanBuffer input(*context, depth.bytes().size());
  vk::VulkanBuffer output(*context, depth.bytes().size());
  DepthMap vulkan_result(width, height);
  DepthMap cpu_result;
  std::vector<double> gpu_ms;

  const auto ours = [&] {
    transfer.upload(depth.bytes(), input);
    if (const auto ms = filter.run(input, output, width, height)) gpu_ms.push_back(*ms);
    transfer.download(output, vulkan_result.bytes());
  };
  const auto baseline = [&] { relight::reconstruct::depth_box_filter(depth, cpu_result); };
  const auto comparison = relight::bench::compare_interleaved(ours, baseline, options.repetitions);
  const double dispatch_ms =
      relight::bench::median_ms([&] { (void)filter.run(input, output, width, height); }, options.repetitions);

  float max_abs_diff = 0.f;
  for (std::size_t i = 0; i < depth.size(); ++i) {
    max_abs_diff = std::max(max_abs_diff, std::fabs(vulkan_result.pixels()[i] - cpu_result.pixels()[i]));
  }

  auto json = relight::bench::comparison_json(comparison, "cpu_reference");
  json["gpu_ms"] = median(gpu_ms);
  json["dispatch_ms"] = dispatch_ms;
  json["max_abs_diff"] = max_abs_diff;
  json["width"] = width;
  json["height"] = height;
  json["device"] = context->device_info().name;
  json["device_type"] = vk::to_string(context->device_info().type);
  json["auto_backend"] = relight::to_string(vk::choose_backend(vk::StageKind::PerPixel, context.get()));
  return json;
}

}  // namespace

RELIGHT_BENCH_CASE("vk/box3x3_vs_cpu", box3x3_vs_cpu);
