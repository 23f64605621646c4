// Vulkan implementation of the statistics-based mapping (statistics_transfer_vk.h).
#include <string>
#include <vector>

#include "relight/colormap/colormap_shared.h"
#include "relight/colormap/statistics_transfer_vk.h"
#include "relight/core/error.h"
#include "relight/shaders/colormap_statistics_comp.h"
#include "relight/shaders/colormap_statistics_transfer_comp.h"
#include "relight/vk/buffer.h"
#include "relight/vk/compute_pipeline.h"
#include "relight/vk/context.h"
#include "relight/vk/timer.h"
#include "relight/vk/transfer.h"

namespace relight::colormap {

namespace {

constexpr std::uint32_t kGroup = RELIGHT_COLORMAP_STATS_GROUP;
constexpr std::uint32_t kStride = RELIGHT_COLORMAP_SUMS_STRIDE;

gpu::ColormapToneMap shader_tone_map(const ToneMap& tm) {
  return {tm.exposure, compression(tm), tm.inverse_white_squared};
}

std::uint32_t checked_pixels(int width, int height) {
  if (width < 0 || height < 0) throw Error("colormap (Vulkan): negative image size");
  const auto pixels = static_cast<std::uint64_t>(width) * static_cast<std::uint64_t>(height);
  if (pixels % 4 != 0) {
    throw Error("colormap (Vulkan): width * height must be a multiple of 4 (got " + std::to_string(width) + "x" +
                std::to_string(height) + ")");
  }
  if (pixels / kGroup >= 65535) throw Error("colormap (Vulkan): image too large for one dispatch");
  return static_cast<std::uint32_t>(pixels);
}

void require_size(const vk::VulkanBuffer& buffer, std::size_t bytes, const char* what) {
  if (buffer.size_bytes() < bytes) throw LogicError(std::string("StatisticsColorMapVk: buffer too small: ") + what);
}

}  // namespace

struct StatisticsColorMapVk::Pipelines {
  explicit Pipelines(vk::VulkanContext& context)
      : statistics(context, {.spirv = shaders::colormap_statistics_comp,
                             .storage_buffers = 4,
                             .push_constant_bytes = sizeof(gpu::ColormapStatisticsParams),
                             .max_descriptor_sets = 4}),
        transfer(context, {.spirv = shaders::colormap_statistics_transfer_comp,
                           .storage_buffers = 3,
                           .push_constant_bytes = sizeof(gpu::ColormapTransferParams),
                           .max_descriptor_sets = 4}),
        timer(context) {}
  vk::ComputePipeline statistics;
  vk::ComputePipeline transfer;
  vk::GpuTimer timer;
  std::optional<vk::VulkanBuffer> sums;  // grown on demand, one row per work group
};

StatisticsColorMapVk::StatisticsColorMapVk(vk::VulkanContext& context)
    : context_(context), pipelines_(std::make_unique<Pipelines>(context)) {}

StatisticsColorMapVk::~StatisticsColorMapVk() = default;

LabSums StatisticsColorMapVk::reduce(const vk::VulkanBuffer& real, const vk::VulkanBuffer& real_virtual,
                                     const vk::VulkanBuffer& camera, int width, int height) {
  const std::uint32_t pixels = checked_pixels(width, height);
  require_size(real, pixels * sizeof(Float3), "L_r");
  require_size(real_virtual, pixels * sizeof(Float3), "L_rv");
  require_size(camera, pixels * sizeof(Rgb8), "camera");
  last_gpu_ms_.reset();
  LabSums total;
  if (pixels == 0) return total;

  const std::uint32_t groups = vk::ComputePipeline::group_count(pixels, kGroup);
  const std::size_t sums_bytes = static_cast<std::size_t>(groups) * kStride * sizeof(float);
  if (!pipelines_->sums || pipelines_->sums->size_bytes() < sums_bytes) pipelines_->sums.emplace(context_, sums_bytes);
  const gpu::ColormapStatisticsParams params{pixels, shader_tone_map(tm_)};
  const auto set = pipelines_->statistics.bind({&real, &real_virtual, &camera, &*pipelines_->sums});
  context_.submit([&](VkCommandBuffer cmd) {
    pipelines_->timer.start(cmd);
    pipelines_->statistics.dispatch(cmd, set, params, groups, 1);
    pipelines_->timer.stop(cmd);
  });
  last_gpu_ms_ = pipelines_->timer.elapsed_ms();

  std::vector<float> rows(static_cast<std::size_t>(groups) * kStride);
  context_.transfer().download(*pipelines_->sums, std::as_writable_bytes(std::span<float>(rows)));
  for (std::uint32_t g = 0; g < groups; ++g) {
    const float* row = rows.data() + static_cast<std::size_t>(g) * kStride;
    total.count += static_cast<std::int64_t>(row[0] + 0.5f);  // <= 256: exact in float
    for (int k = 0; k < 3; ++k) {
      total.source_sum[k] += row[1 + k];
      total.source_sum_sq[k] += row[4 + k];
      total.target_sum[k] += row[7 + k];
      total.target_sum_sq[k] += row[10 + k];
    }
  }
  return total;
}

void StatisticsColorMapVk::transfer(const vk::VulkanBuffer& real, const vk::VulkanBuffer& real_virtual,
                                    const ReinhardTransfer& transfer, vk::VulkanBuffer& delta, int width,
                                    int height) {
  const std::uint32_t pixels = checked_pixels(width, height);
  require_size(real, pixels * sizeof(Float3), "L_r");
  require_size(real_virtual, pixels * sizeof(Float3), "L_rv");
  require_size(delta, pixels * sizeof(Float3), "delta_L");
  if (pixels == 0) return;
  gpu::ColormapTransferParams params{};
  params.pixels = pixels;
  params.tone_map = shader_tone_map(tm_);
  for (int k = 0; k < 3; ++k) {
    params.scale[k] = transfer.scale[k];
    params.offset[k] = transfer.offset[k];
  }
  const auto set = pipelines_->transfer.bind({&real, &real_virtual, &delta});
  context_.submit([&](VkCommandBuffer cmd) {
    pipelines_->timer.start(cmd);
    pipelines_->transfer.dispatch(cmd, set, params, vk::ComputePipeline::group_count(pixels, kGroup), 1);
    pipelines_->timer.stop(cmd);
  });
  if (const auto ms = pipelines_->timer.elapsed_ms()) last_gpu_ms_ = last_gpu_ms_.value_or(0.0) + *ms;
}

ReinhardTransfer StatisticsColorMapVk::run(const vk::VulkanBuffer& real, const vk::VulkanBuffer& real_virtual,
                                           const vk::VulkanBuffer& camera, vk::VulkanBuffer& delta, int width,
                                           int height) {
  const ReinhardTransfer mapping =
      ReinhardTransfer::from(statistics_from_sums(reduce(real, real_virtual, camera, width, height)));
  transfer(real, real_virtual, mapping, delta, width, height);
  return mapping;
}

ReinhardTransfer StatisticsColorMapVk::run(const RadianceImage& real, const RadianceImage& real_virtual,
                                           const ColorImage& camera, RadianceImage& delta) {
  if (!real.same_shape(real_virtual) || !real.same_shape(camera)) {
    throw Error("colormap: L_r, L_rv and the camera image must have the same size");
  }
  vk::VulkanTransfer& mover = context_.transfer();
  vk::VulkanBuffer real_device(context_, real.bytes().size());
  vk::VulkanBuffer virtual_device(context_, real_virtual.bytes().size());
  vk::VulkanBuffer camera_device(context_, camera.bytes().size());
  vk::VulkanBuffer delta_device(context_, real.bytes().size());
  mover.upload(real.bytes(), real_device);
  mover.upload(real_virtual.bytes(), virtual_device);
  mover.upload(camera.bytes(), camera_device);
  const ReinhardTransfer mapping =
      run(real_device, virtual_device, camera_device, delta_device, real.width(), real.height());
  delta.resize(real.width(), real.height());
  mover.download(delta_device, delta.bytes());
  return mapping;
}

}  // namespace relight::colormap
