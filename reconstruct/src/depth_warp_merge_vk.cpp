// Method 2's warp and merge on Vulkan (depth_warp_merge_vk.h): clear, scatter depths, scatter
// weights, merge, in one submission with a barrier between the passes.
#include "relight/reconstruct/depth_warp_merge_vk.h"

#include "relight/reconstruct/depth_warp_merge_shared.h"
#include "relight/shaders/depth_merge_comp.h"
#include "relight/shaders/depth_warp_comp.h"
#include "relight/vk/barrier.h"
#include "relight/vk/buffer.h"
#include "relight/vk/compute_pipeline.h"
#include "relight/vk/context.h"
#include "relight/vk/timer.h"
#include "relight/vk/transfer.h"

namespace relight {

struct DepthWarpMergeVk::Pipelines {
  explicit Pipelines(vk::VulkanContext& context)
      : warp(context, {.spirv = shaders::depth_warp_comp, .storage_buffers = 4,
                       .push_constant_bytes = sizeof(gpu::DepthWarpParams), .max_descriptor_sets = 2}),
        merge(context, {.spirv = shaders::depth_merge_comp, .storage_buffers = 5,
                        .push_constant_bytes = sizeof(gpu::DepthMergeParams), .max_descriptor_sets = 2}),
        timer(context) {}
  vk::ComputePipeline warp;
  vk::ComputePipeline merge;
  vk::GpuTimer timer;
};

DepthWarpMergeVk::DepthWarpMergeVk(vk::VulkanContext& context)
    : context_(context), pipelines_(std::make_unique<Pipelines>(context)) {}

DepthWarpMergeVk::~DepthWarpMergeVk() = default;

void DepthWarpMergeVk::run(const DepthMap& depth, const DepthMap* previous_depth, const DepthWeightMap* previous_weight,
                           const PinholeIntrinsics& intrinsics, const Pose& current_from_prev,
                           const DepthWarpMergeOptions& options, DepthMap& merged, DepthWeightMap& merged_weight) {
  const int width = depth.width(), height = depth.height();
  merged.resize(width, height);
  merged_weight.resize(width, height);
  last_gpu_ms_.reset();
  if (depth.empty()) return;
  const bool history = previous_depth && previous_depth->same_shape(depth);
  const bool has_weight = history && previous_weight && previous_weight->same_shape(depth);
  const std::size_t bytes = depth.bytes().size();
  vk::VulkanTransfer& transfer = context_.transfer();
  vk::VulkanBuffer depth_buffer(context_, bytes), previous_buffer(context_, bytes), previous_weight_buffer(context_, bytes);
  vk::VulkanBuffer zbuffer(context_, bytes), warped_weight(context_, bytes);
  vk::VulkanBuffer merged_buffer(context_, bytes), merged_weight_buffer(context_, bytes);
  transfer.upload(depth.bytes(), depth_buffer);
  if (history) transfer.upload(previous_depth->bytes(), previous_buffer);
  if (has_weight) transfer.upload(previous_weight->bytes(), previous_weight_buffer);

  gpu::DepthWarpParams warp{};
  warp.width = static_cast<gpu::uint>(width);
  warp.height = static_cast<gpu::uint>(height);
  warp.has_weight = has_weight ? 1u : 0u;
  warp.fx = static_cast<float>(intrinsics.fx);
  warp.fy = static_cast<float>(intrinsics.fy);
  warp.cx = static_cast<float>(intrinsics.cx);
  warp.cy = static_cast<float>(intrinsics.cy);
  warp.max_edge_m = options.max_edge_m;
  warp.max_edge_rel = options.max_edge_rel;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) warp.current_from_prev[r * 4 + c] = static_cast<float>(current_from_prev.matrix()(r, c));
  const gpu::DepthMergeParams merge{warp.width, warp.height, options.merge_threshold_m, options.max_weight};

  Pipelines& p = *pipelines_;
  constexpr std::uint32_t local = RELIGHT_DEPTH_WARP_LOCAL_SIZE;
  const std::uint32_t groups_x = vk::ComputePipeline::group_count(warp.width, local);
  const std::uint32_t groups_y = vk::ComputePipeline::group_count(warp.height, local);
  const auto warp_set = p.warp.bind({&previous_buffer, &previous_weight_buffer, &zbuffer, &warped_weight});
  const auto merge_set = p.merge.bind({&depth_buffer, &zbuffer, &warped_weight, &merged_buffer, &merged_weight_buffer});
  context_.submit([&](VkCommandBuffer cmd) {
    p.timer.start(cmd);
    warp.mode = RELIGHT_DEPTH_WARP_CLEAR;
    p.warp.dispatch(cmd, warp_set, warp, groups_x, groups_y);
    if (history) {
      for (const gpu::uint mode : {gpu::uint{RELIGHT_DEPTH_WARP_DEPTH}, gpu::uint{RELIGHT_DEPTH_WARP_WEIGHT}}) {
        vk::compute_barrier(cmd);
        warp.mode = mode;
        p.warp.dispatch(cmd, warp_set, warp, groups_x, groups_y);
      }
    }
    vk::compute_barrier(cmd);
    p.merge.dispatch(cmd, merge_set, merge, groups_x, groups_y);
    p.timer.stop(cmd);
  });
  last_gpu_ms_ = p.timer.elapsed_ms();
  transfer.download(merged_buffer, merged.bytes());
  transfer.download(merged_weight_buffer, merged_weight.bytes());
}

void DepthWarpMergeVkStage::warp_and_merge(StageContext& context, const DepthMap& depth, const DepthMap* previous_depth,
                                           const DepthWeightMap* previous_weight, const PinholeIntrinsics& intrinsics,
                                           const Pose& current_from_prev, DepthMap& merged,
                                           DepthWeightMap& merged_weight) {
  method_.run(depth, previous_depth, previous_weight, intrinsics, current_from_prev, options(), merged, merged_weight);
  if (const auto ms = method_.last_gpu_ms()) context.report_device_ms(*ms);
}

}  // namespace relight
