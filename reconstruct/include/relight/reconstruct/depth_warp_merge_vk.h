#pragma once
// Method 2's warp and merge (definition and CPU reference in depth_warp_merge.h) on Vulkan:
//   1. shaders/depth_warp.comp scatters the previous depth's vertex grid mesh: one invocation per
//      cell rasterises its two triangles with the CPU rasteriser's rules into a z-buffer by
//      atomic min on float bits, then a second pass writes the weights of the winning triangles
//      (the "equivalent compute scatter with atomic min depth" of the issue; no graphics
//      pipeline, so no rasteriser rules to reconcile with the CPU reference);
//   2. shaders/depth_merge.comp merges the new raw depth with the warped history per pixel.
// The result equals the CPU's except where float rounding puts a pixel centre on the other side
// of a triangle edge, or two triangles tie exactly (either weight may win), and σ_z is float.
//
// Reads:  depth, the previous filtered depth and weight (null on the first frame; ignored when
//         the shape differs), intrinsics, T_current_from_prev (depth_warp_merge.h), options
//         (threads is ignored).
// Writes: the merged depth and weight.
// In the frame graph (DepthWarpMergeVkStage) all four maps stay on the device: the graph uploads
// the raw depth, keeps the filtered depth and weight as device-resident history, and downloads
// only for a CPU reader. The warp's z-buffer and weights are scratch kept across frames, so a
// steady run allocates no device memory.
// This header includes no Vulkan headers.
#include <memory>
#include <optional>

#include "relight/core/camera.h"
#include "relight/core/image.h"
#include "relight/core/pose.h"
#include "relight/reconstruct/depth_warp_merge.h"

namespace relight::vk {
class VulkanBuffer;
class VulkanContext;
}  // namespace relight::vk

namespace relight::reconstruct {

/// Holds the pipelines: create once, reuse every frame.
class DepthWarpMergeVk {
 public:
  explicit DepthWarpMergeVk(vk::VulkanContext& context);
  ~DepthWarpMergeVk();
  DepthWarpMergeVk(const DepthWarpMergeVk&) = delete;
  DepthWarpMergeVk& operator=(const DepthWarpMergeVk&) = delete;

  /// One frame on host maps (uploads, dispatches in one submission, downloads). Resizes the outputs.
  void run(const DepthMap& depth, const DepthMap* previous_depth, const DepthWeightMap* previous_weight,
           const PinholeIntrinsics& intrinsics, const Pose& current_from_prev, const DepthWarpMergeOptions& options,
           DepthMap& merged, DepthWeightMap& merged_weight);
  /// One frame on device buffers of width x height floats each; the previous maps are both null
  /// (no history) or both set (previous_weight may then be null: no weights yet).
  void run(const vk::VulkanBuffer& depth, const vk::VulkanBuffer* previous_depth,
           const vk::VulkanBuffer* previous_weight, int width, int height, const PinholeIntrinsics& intrinsics,
           const Pose& current_from_prev, const DepthWarpMergeOptions& options, vk::VulkanBuffer& merged,
           vk::VulkanBuffer& merged_weight);
  /// GPU time of the last run()'s dispatches, if the device has timestamps.
  [[nodiscard]] std::optional<double> last_gpu_ms() const { return last_gpu_ms_; }

 private:
  struct Pipelines;
  struct Scratch;
  vk::VulkanContext& context_;
  std::unique_ptr<Pipelines> pipelines_;
  std::unique_ptr<Scratch> scratch_;
  std::optional<double> last_gpu_ms_;
};

/// Frame-graph stage of method 2's warp and merge on Vulkan, a drop-in for
/// DepthWarpMergeCpuStage (same name and buffers): its maps live on the device (backend() is
/// Vulkan), the history included, and it reports the GPU time of its dispatches.
class DepthWarpMergeVkStage final : public DepthWarpMergeStageBase {
 public:
  explicit DepthWarpMergeVkStage(vk::VulkanContext& context, DepthWarpMergeOptions options = {})
      : DepthWarpMergeStageBase(options), method_(context) {}
  [[nodiscard]] Backend backend() const override { return Backend::Vulkan; }
  void run(StageContext& context) override;

 private:
  DepthWarpMergeVk method_;
};

}  // namespace relight::reconstruct
