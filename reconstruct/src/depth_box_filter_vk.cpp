// Vulkan implementation of the depth box filter (definition in depth_box_filter.h): one
// invocation per pixel, shaders/depth_box_filter.comp, embedded at build time.
#include "relight/core/error.h"
#include "relight/core/stage_backend.h"
#include "relight/reconstruct/depth_box_filter.h"
#include "relight/reconstruct/depth_box_filter_shared.h"
#include "relight/shaders/depth_box_filter_comp.h"
#include "relight/vk/buffer.h"
#include "relight/vk/compute_pipeline.h"
#include "relight/vk/context.h"
#include "relight/vk/timer.h"
#include "relight/vk/transfer.h"

namespace relight::reconstruct {

struct DepthBoxFilterVk::Pipeline {
  explicit Pipeline(vk::VulkanContext& context)
      : compute(context, {.spirv = shaders::depth_box_filter_comp,
                          .storage_buffers = 2,
                          .push_constant_bytes = sizeof(gpu::DepthBoxFilterParams),
                          .max_descriptor_sets = 4}),
        timer(context) {}
  vk::ComputePipeline compute;
  vk::GpuTimer timer;
};

DepthBoxFilterVk::DepthBoxFilterVk(vk::VulkanContext& context)
    : context_(context), pipeline_(std::make_unique<Pipeline>(context)) {}

DepthBoxFilterVk::~DepthBoxFilterVk() = default;

std::optional<double> DepthBoxFilterVk::run(const vk::VulkanBuffer& depth, vk::VulkanBuffer& smoothed, int width,
                                            int height) {
  const std::size_t bytes = static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * sizeof(float);
  if (width < 0 || height < 0 || depth.size_bytes() < bytes || smoothed.size_bytes() < bytes) {
    throw LogicError("DepthBoxFilterVk::run: buffers smaller than width*height floats");
  }
  last_gpu_ms_.reset();
  if (bytes == 0) return last_gpu_ms_;

  const gpu::DepthBoxFilterParams params{static_cast<gpu::uint>(width), static_cast<gpu::uint>(height)};
  constexpr std::uint32_t local = RELIGHT_DEPTH_BOX_FILTER_LOCAL_SIZE;
  const auto set = pipeline_->compute.bind({&depth, &smoothed});
  context_.submit([&](VkCommandBuffer cmd) {
    pipeline_->timer.start(cmd);
    pipeline_->compute.dispatch(cmd, set, params, vk::ComputePipeline::group_count(params.width, local),
                                vk::ComputePipeline::group_count(params.height, local));
    pipeline_->timer.stop(cmd);
  });
  last_gpu_ms_ = pipeline_->timer.elapsed_ms();
  return last_gpu_ms_;
}

DepthMap DepthBoxFilterVk::run(const DepthMap& depth) {
  vk::VulkanTransfer& transfer = context_.transfer();
  vk::VulkanBuffer input(context_, depth.bytes().size());
  vk::VulkanBuffer output(context_, depth.bytes().size());
  transfer.upload(depth.bytes(), input);
  run(input, output, depth.width(), depth.height());
  DepthMap smoothed(depth.width(), depth.height());
  transfer.download(output, smoothed.bytes());
  return smoothed;
}

DepthBoxFilterVkStage::DepthBoxFilterVkStage(vk::VulkanContext& context, DepthBoxFilterBuffers buffers)
    : filter_(context), buffers_(std::move(buffers)) {}

void DepthBoxFilterVkStage::declare(StageBuilder& builder) {
  input_ = builder.read(buffers_.input);
  output_ = builder.write(buffers_.output);
}

void DepthBoxFilterVkStage::run(StageContext& context) {
  auto& input = context.device_read<vk::VulkanBuffer>(input_);
  // Only the shape is needed on the host; shape_of never downloads device-side pixels.
  const DepthMap& host_input = context.shape_of(input_);
  const int width = host_input.width();
  const int height = host_input.height();
  auto& output = context.device_write<vk::VulkanBuffer>(output_, [&](DepthMap& out) { out.resize(width, height); });
  if (const auto gpu_ms = filter_.run(input, output, width, height)) context.report_device_ms(*gpu_ms);
}

std::unique_ptr<Stage> make_depth_box_filter_stage(Backend backend, vk::VulkanContext* context,
                                                   DepthBoxFilterBuffers buffers) {
  return make_stage_for_backend<DepthBoxFilterCpuStage, DepthBoxFilterVkStage>(backend, context,
                                                                               "make_depth_box_filter_stage", buffers);
}

}  // namespace relight::reconstruct
