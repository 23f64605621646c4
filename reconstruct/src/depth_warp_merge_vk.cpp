// Method 2's warp and merge on Vulkan (depth_warp_merge_vk.h): clear, scatter depths, scatter
// weights, merge, in one submission with a barrier between the passes.
#include "relight/reconstruct/depth_warp_merge_vk.h"

#include <optional>

#include "relight/reconstruct/depth_warp_merge_shared.h"
#include "relight/shaders/depth_merge_comp.h"
#include "relight/shaders/depth_warp_comp.h"
#include "relight/vk/barrier.h"
#include "relight/vk/buffer.h"
#include "relight/vk/compute_pipeline.h"
#include "relight/vk/context.h"
#include "relight/vk/timer.h"
#include "relight/vk/transfer.h"

namespace relight::reconstruct {

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

/// Device buffers kept across frames (remade only when the frame size changes): the warp's
/// z-buffer and weights, a stand-in bound where there is no history, and the maps of the host API.
struct DepthWarpMergeVk::Scratch {
  std::optional<vk::VulkanBuffer> zbuffer, warped_weight, no_history;
  std::optional<vk::VulkanBuffer> depth, previous_depth, previous_weight, merged, merged_weight;
};

DepthWarpMergeVk::DepthWarpMergeVk(vk::VulkanContext& context)
    : context_(context), pipelines_(std::make_unique<Pipelines>(context)), scratch_(std::make_unique<Scratch>()) {}

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
  Scratch& s = *scratch_;
  transfer.upload(depth.bytes(), vk::buffer_of_size(s.depth, context_, bytes));
  if (history) transfer.upload(previous_depth->bytes(), vk::buffer_of_size(s.previous_depth, context_, bytes));
  if (has_weight) transfer.upload(previous_weight->bytes(), vk::buffer_of_size(s.previous_weight, context_, bytes));
  run(*s.depth, history ? &*s.previous_depth : nullptr, has_weight ? &*s.previous_weight : nullptr, width, height,
      intrinsics, current_from_prev, options, vk::buffer_of_size(s.merged, context_, bytes),
      vk::buffer_of_size(s.merged_weight, context_, bytes));
  transfer.download(*s.merged, merged.bytes());
  transfer.download(*s.merged_weight, merged_weight.bytes());
}

void DepthWarpMergeVk::run(const vk::VulkanBuffer& depth, const vk::VulkanBuffer* previous_depth,
                           const vk::VulkanBuffer* previous_weight, int width, int height,
                           const PinholeIntrinsics& intrinsics, const Pose& current_from_prev,
                           const DepthWarpMergeOptions& options, vk::VulkanBuffer& merged,
                           vk::VulkanBuffer& merged_weight) {
  last_gpu_ms_.reset();
  const std::size_t bytes = static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * sizeof(float);
  if (bytes == 0) return;
  const bool history = previous_depth != nullptr;
  const bool has_weight = history && previous_weight != nullptr;
  Scratch& s = *scratch_;
  vk::VulkanBuffer& zbuffer = vk::buffer_of_size(s.zbuffer, context_, bytes);
  vk::VulkanBuffer& warped_weight = vk::buffer_of_size(s.warped_weight, context_, bytes);
  // Bound where a map is missing; the shaders do not read it then (no history: only the clear
  // pass runs; no weights: has_weight = 0).
  vk::VulkanBuffer& unused = vk::buffer_of_size(s.no_history, context_, bytes);

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
  const auto warp_set = p.warp.bind(
      {history ? previous_depth : &unused, has_weight ? previous_weight : &unused, &zbuffer, &warped_weight});
  const auto merge_set = p.merge.bind({&depth, &zbuffer, &warped_weight, &merged, &merged_weight});
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
}

void DepthWarpMergeVkStage::run(StageContext& context) {
  const DepthMap& depth_shape = context.shape_of(depth_);
  const int width = depth_shape.width(), height = depth_shape.height();
  const DepthMap* previous_shape = context.shape_of(previous_depth_);
  const DepthWeightMap* previous_weight_shape = context.shape_of(previous_weight_);
  const bool usable = previous_shape && previous_weight_shape && previous_shape->same_shape(depth_shape);
  const vk::VulkanBuffer* previous_depth = usable ? context.device_read<vk::VulkanBuffer>(previous_depth_) : nullptr;
  const vk::VulkanBuffer* previous_weight = usable ? context.device_read<vk::VulkanBuffer>(previous_weight_) : nullptr;
  const vk::VulkanBuffer& depth = context.device_read<vk::VulkanBuffer>(depth_);
  auto& merged = context.device_write<vk::VulkanBuffer>(filtered_, [&](DepthMap& d) { d.resize(width, height); });
  auto& merged_weight =
      context.device_write<vk::VulkanBuffer>(weight_, [&](DepthWeightMap& w) { w.resize(width, height); });
  method_.run(depth, previous_depth, previous_weight, width, height, context.get(frame_).intrinsics,
              current_from_previous(context), options(), merged, merged_weight);
  if (const auto ms = method_.last_gpu_ms()) context.report_device_ms(*ms);
}

std::unique_ptr<Stage> make_depth_warp_merge_stage(Backend backend, vk::VulkanContext* context,
                                                   DepthWarpMergeOptions options) {
  return make_stage_for_backend<DepthWarpMergeCpuStage, DepthWarpMergeVkStage>(backend, context,
                                                                               "make_depth_warp_merge_stage", options);
}

}  // namespace relight::reconstruct
