// Vulkan method 1 (definition in normals_raw_depth.h, API in normals_raw_depth_vk.h).
#include <optional>
#include <vector>

#include "relight/core/error.h"
#include "relight/reconstruct/normals_blend_shared.h"
#include "relight/reconstruct/normals_raw_depth_vk.h"
#include "relight/shaders/normals_blend_comp.h"
#include "relight/shaders/normals_fill_holes_comp.h"
#include "relight/vk/buffer.h"
#include "relight/vk/compute_pipeline.h"
#include "relight/vk/context.h"
#include "relight/vk/timer.h"
#include "relight/vk/transfer.h"

namespace relight {

struct NormalsRawDepthVk::Pipelines {
  explicit Pipelines(vk::VulkanContext& context)
      : blend(context, {.spirv = shaders::normals_blend_comp,
                        .storage_buffers = 6,
                        .push_constant_bytes = sizeof(gpu::NormalsBlendParams),
                        .max_descriptor_sets = 4}),
        fill(context, {.spirv = shaders::normals_fill_holes_comp,
                       .storage_buffers = 3,
                       .push_constant_bytes = sizeof(gpu::NormalsFillParams),
                       .max_descriptor_sets = 4}),
        timer(context) {}
  vk::ComputePipeline blend;
  vk::ComputePipeline fill;
  vk::GpuTimer timer;
};

/// Device buffers kept across frames, remade only when a size changes: a steady run allocates
/// no device memory.
struct NormalsRawDepthVk::Scratch {
  std::optional<vk::VulkanBuffer> depth, positions, normals, blended, previous_positions, pyramid, curvature;
};

NormalsRawDepthVk::NormalsRawDepthVk(vk::VulkanContext& context)
    : context_(context),
      cross_(context),
      pipelines_(std::make_unique<Pipelines>(context)),
      scratch_(std::make_unique<Scratch>()) {}

NormalsRawDepthVk::~NormalsRawDepthVk() = default;

void NormalsRawDepthVk::run(const DepthMap& depth, const PinholeIntrinsics& intrinsics, const Pose& camera_to_world,
                            const NormalsHistory* previous, const NormalsRawDepthOptions& options,
                            PositionMap& positions, NormalMap& normals) {
  const int width = depth.width(), height = depth.height();
  positions.resize(width, height);
  normals.resize(width, height);
  last_gpu_ms_.reset();
  if (depth.empty()) return;
  const std::size_t map_bytes = positions.bytes().size();
  vk::VulkanTransfer& transfer = context_.transfer();
  Scratch& scratch = *scratch_;
  vk::VulkanBuffer& depth_buffer = vk::buffer_of_size(scratch.depth, context_, depth.bytes().size());
  vk::VulkanBuffer& position_buffer = vk::buffer_of_size(scratch.positions, context_, map_bytes);
  vk::VulkanBuffer& normal_buffer = vk::buffer_of_size(scratch.normals, context_, map_bytes);
  vk::VulkanBuffer& blended_buffer = vk::buffer_of_size(scratch.blended, context_, map_bytes);
  transfer.upload(depth.bytes(), depth_buffer);
  std::optional<double> total =
      cross_.run(depth_buffer, position_buffer, normal_buffer, width, height, intrinsics,
                 cross_normal_options(options));

  const bool usable_history = previous && previous->normals.same_shape(depth) && previous->positions.same_shape(depth);
  // Without history the blend is the identity: let the fill pass read the fresh normals directly.
  const vk::VulkanBuffer* fill_input = &normal_buffer;
  if (usable_history) {
    const std::vector<NormalsPyramidLevel> pyramid =
        normals_history_pyramid(previous->normals, options.mip_levels, options.threads);
    std::vector<Float3> texels;
    for (const auto& level : pyramid) texels.insert(texels.end(), level.normal.pixels().begin(), level.normal.pixels().end());
    vk::VulkanBuffer& previous_positions = vk::buffer_of_size(scratch.previous_positions, context_, map_bytes);
    vk::VulkanBuffer& pyramid_buffer = vk::buffer_of_size(scratch.pyramid, context_, texels.size() * sizeof(Float3));
    vk::VulkanBuffer& curvature_buffer =
        vk::buffer_of_size(scratch.curvature, context_, pyramid.front().curvature.bytes().size());
    transfer.upload(previous->positions.bytes(), previous_positions);
    transfer.upload(std::as_bytes(std::span<const Float3>(texels)), pyramid_buffer);
    transfer.upload(pyramid.front().curvature.bytes(), curvature_buffer);

    // The same float matrices as the CPU's Rigid (pose in double, rounded per element).
    const Pose prev_from_current = previous->camera_to_world.inverse() * camera_to_world;
    const Pose current_from_prev = prev_from_current.inverse();
    gpu::NormalsBlendParams params{};
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c) params.prev_from_current[r * 4 + c] = static_cast<float>(prev_from_current.matrix()(r, c));
      for (int c = 0; c < 3; ++c) params.current_from_prev[r * 3 + c] = static_cast<float>(current_from_prev.matrix()(r, c));
    }
    params.fx = static_cast<float>(intrinsics.fx);
    params.fy = static_cast<float>(intrinsics.fy);
    params.cx = static_cast<float>(intrinsics.cx);
    params.cy = static_cast<float>(intrinsics.cy);
    params.blend_base = options.blend_base;
    params.disocclusion_m = options.disocclusion_m;
    params.width = static_cast<gpu::uint>(width);
    params.height = static_cast<gpu::uint>(height);
    params.levels = static_cast<gpu::uint>(pyramid.size());
    constexpr std::uint32_t local = RELIGHT_NORMALS_BLEND_LOCAL_SIZE;
    const auto set = pipelines_->blend.bind(
        {&position_buffer, &normal_buffer, &previous_positions, &pyramid_buffer, &curvature_buffer, &blended_buffer});
    context_.submit([&](VkCommandBuffer cmd) {
      pipelines_->timer.start(cmd);
      pipelines_->blend.dispatch(cmd, set, params, vk::ComputePipeline::group_count(params.width, local),
                                 vk::ComputePipeline::group_count(params.height, local));
      pipelines_->timer.stop(cmd);
    });
    if (const auto ms = pipelines_->timer.elapsed_ms(); ms && total) *total += *ms;
    fill_input = &blended_buffer;
  }

  // Fill reads fill_input and writes the other buffer, so no pixel sees a neighbour's fill.
  vk::VulkanBuffer& fill_output = fill_input == &normal_buffer ? blended_buffer : normal_buffer;
  const gpu::NormalsFillParams fill_params{static_cast<gpu::uint>(width), static_cast<gpu::uint>(height)};
  constexpr std::uint32_t local = RELIGHT_NORMALS_BLEND_LOCAL_SIZE;
  const auto fill_set = pipelines_->fill.bind({&position_buffer, fill_input, &fill_output});
  context_.submit([&](VkCommandBuffer cmd) {
    pipelines_->timer.start(cmd);
    pipelines_->fill.dispatch(cmd, fill_set, fill_params, vk::ComputePipeline::group_count(fill_params.width, local),
                              vk::ComputePipeline::group_count(fill_params.height, local));
    pipelines_->timer.stop(cmd);
  });
  if (const auto ms = pipelines_->timer.elapsed_ms(); ms && total) *total += *ms;
  last_gpu_ms_ = total;
  transfer.download(position_buffer, positions.bytes());
  transfer.download(fill_output, normals.bytes());
}

void NormalsRawDepthVkStage::estimate(StageContext& context, const DepthMap& depth,
                                      const PinholeIntrinsics& intrinsics, const Pose& camera_to_world,
                                      const NormalsHistory* previous, PositionMap& positions, NormalMap& normals) {
  method_.run(depth, intrinsics, camera_to_world, previous, options(), positions, normals);
  if (const auto ms = method_.last_gpu_ms()) context.report_device_ms(*ms);
}

}  // namespace relight
