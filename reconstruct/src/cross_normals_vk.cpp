// Vulkan implementation of positions + cross-product normals (definition in
// normals_from_positions.h, API in cross_normals_vk.h): one invocation per pixel,
// shaders/cross_normals.comp, embedded at build time.
#include "relight/reconstruct/cross_normals_vk.h"
#include "relight/core/buffers.h"
#include "relight/core/error.h"
#include "relight/core/pixel.h"
#include "relight/reconstruct/cross_normals_shared.h"
#include "relight/shaders/cross_normals_comp.h"
#include "relight/vk/buffer.h"
#include "relight/vk/compute_pipeline.h"
#include "relight/vk/context.h"
#include "relight/vk/timer.h"
#include "relight/vk/transfer.h"

namespace relight::reconstruct {

static_assert(sizeof(Float3) == 3 * sizeof(float), "the shader indexes Float3 maps as 3 packed floats");

struct CrossNormalsVk::Pipeline {
  explicit Pipeline(vk::VulkanContext& context)
      : compute(context, {.spirv = shaders::cross_normals_comp,
                          .storage_buffers = 3,
                          .push_constant_bytes = sizeof(gpu::CrossNormalsParams),
                          .max_descriptor_sets = 4}),
        timer(context) {}
  vk::ComputePipeline compute;
  vk::GpuTimer timer;
};

CrossNormalsVk::CrossNormalsVk(vk::VulkanContext& context)
    : context_(context), pipeline_(std::make_unique<Pipeline>(context)) {}

CrossNormalsVk::~CrossNormalsVk() = default;

std::optional<double> CrossNormalsVk::run(const vk::VulkanBuffer& depth, vk::VulkanBuffer& positions,
                                          vk::VulkanBuffer& normals, int width, int height,
                                          const PinholeIntrinsics& intrinsics, const CrossNormalOptions& options) {
  if (width < 0 || height < 0) throw LogicError("CrossNormalsVk::run: negative image size");
  if (options.stride < 1) throw LogicError("CrossNormalsVk::run: stride must be >= 1");
  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  if (depth.size_bytes() < pixels * sizeof(float) || positions.size_bytes() < pixels * sizeof(Float3) ||
      normals.size_bytes() < pixels * sizeof(Float3)) {
    throw LogicError("CrossNormalsVk::run: buffers smaller than the image");
  }
  last_gpu_ms_.reset();
  if (pixels == 0) return last_gpu_ms_;

  // Same float constants as positions_from_depth, so positions match bit for bit.
  const gpu::CrossNormalsParams params{static_cast<gpu::uint>(width),
                                       static_cast<gpu::uint>(height),
                                       options.stride,
                                       options.max_jump_rel,
                                       static_cast<float>(1.0 / intrinsics.fx),
                                       static_cast<float>(1.0 / intrinsics.fy),
                                       static_cast<float>(intrinsics.cx),
                                       static_cast<float>(intrinsics.cy),
                                       options.centred ? 1u : 0u};
  constexpr std::uint32_t local = RELIGHT_CROSS_NORMALS_LOCAL_SIZE;
  const auto set = pipeline_->compute.bind({&depth, &positions, &normals});
  context_.submit([&](VkCommandBuffer cmd) {
    pipeline_->timer.start(cmd);
    pipeline_->compute.dispatch(cmd, set, params, vk::ComputePipeline::group_count(params.width, local),
                                vk::ComputePipeline::group_count(params.height, local));
    pipeline_->timer.stop(cmd);
  });
  last_gpu_ms_ = pipeline_->timer.elapsed_ms();
  return last_gpu_ms_;
}

void CrossNormalsVk::run(const DepthMap& depth, const PinholeIntrinsics& intrinsics, const CrossNormalOptions& options,
                         PositionMap& positions, NormalMap& normals) {
  positions.resize(depth.width(), depth.height());
  normals.resize(depth.width(), depth.height());
  vk::VulkanTransfer& transfer = context_.transfer();
  vk::VulkanBuffer input(context_, depth.bytes().size());
  vk::VulkanBuffer position_buffer(context_, positions.bytes().size());
  vk::VulkanBuffer normal_buffer(context_, normals.bytes().size());
  transfer.upload(depth.bytes(), input);
  run(input, position_buffer, normal_buffer, depth.width(), depth.height(), intrinsics, options);
  transfer.download(position_buffer, positions.bytes());
  transfer.download(normal_buffer, normals.bytes());
}

void NormalsFromPositionsVkStage::declare(StageBuilder& builder) {
  depth_ = builder.read(kDepthFiltered);
  frame_ = builder.read(kFrame);
  positions_ = builder.write(kPositions);
  normals_ = builder.write(kNormals);
}

void NormalsFromPositionsVkStage::run(StageContext& context) {
  // All three maps stay on the device: after method 2's Vulkan warp and merge the merged depth is
  // already there, and the graph downloads positions and normals only for a CPU reader.
  const DepthMap& shape = context.shape_of(depth_);
  const int width = shape.width(), height = shape.height();
  const auto& depth = context.device_read<vk::VulkanBuffer>(depth_);
  auto& positions =
      context.device_write<vk::VulkanBuffer>(positions_, [&](PositionMap& p) { p.resize(width, height); });
  auto& normals = context.device_write<vk::VulkanBuffer>(normals_, [&](NormalMap& n) { n.resize(width, height); });
  if (width > 0 && height > 0) {
    cross_.run(depth, positions, normals, width, height, context.get(frame_).intrinsics, options_);
    if (const auto ms = cross_.last_gpu_ms()) context.report_device_ms(*ms);
  }
}

std::unique_ptr<Stage> make_normals_from_positions_stage(Backend backend, vk::VulkanContext* context,
                                                         CrossNormalOptions options) {
  return make_stage_for_backend<NormalsFromPositionsCpuStage, NormalsFromPositionsVkStage>(
      backend, context, "make_normals_from_positions_stage", options);
}

}  // namespace relight::reconstruct
