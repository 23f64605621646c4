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
// This header includes no Vulkan headers.
#include <memory>
#include <optional>

#include "relight/core/camera.h"
#include "relight/core/image.h"
#include "relight/core/pose.h"
#include "relight/reconstruct/depth_warp_merge.h"

namespace relight {

namespace vk {
class VulkanContext;
}  // namespace vk

/// Holds the pipelines: create once, reuse every frame.
class DepthWarpMergeVk {
 public:
  explicit DepthWarpMergeVk(vk::VulkanContext& context);
  ~DepthWarpMergeVk();
  DepthWarpMergeVk(const DepthWarpMergeVk&) = delete;
  DepthWarpMergeVk& operator=(const DepthWarpMergeVk&) = delete;

  /// One frame (uploads, dispatches in one submission, downloads). Resizes the outputs.
  void run(const DepthMap& depth, const DepthMap* previous_depth, const DepthWeightMap* previous_weight,
           const PinholeIntrinsics& intrinsics, const Pose& current_from_prev, const DepthWarpMergeOptions& options,
           DepthMap& merged, DepthWeightMap& merged_weight);
  /// GPU time of the last run()'s dispatches, if the device has timestamps.
  [[nodiscard]] std::optional<double> last_gpu_ms() const { return last_gpu_ms_; }

 private:
  struct Pipelines;
  vk::VulkanContext& context_;
  std::unique_ptr<Pipelines> pipelines_;
  std::optional<double> last_gpu_ms_;
};

/// Frame-graph stage of method 2's warp and merge on Vulkan, a drop-in for
/// DepthWarpMergeCpuStage (same name and buffers). Like NormalsRawDepthVkStage it works on the
/// graph's host buffers (the previous frame's buffers reach stages on the host only) and reports
/// the GPU time of its dispatches to the graph's timing table.
class DepthWarpMergeVkStage final : public DepthWarpMergeStageBase {
 public:
  explicit DepthWarpMergeVkStage(vk::VulkanContext& context, DepthWarpMergeOptions options = {})
      : DepthWarpMergeStageBase(options), method_(context) {}

 private:
  void warp_and_merge(StageContext& context, const DepthMap& depth, const DepthMap* previous_depth,
                      const DepthWeightMap* previous_weight, const PinholeIntrinsics& intrinsics,
                      const Pose& current_from_prev, DepthMap& merged, DepthWeightMap& merged_weight) override;
  DepthWarpMergeVk method_;
};

}  // namespace relight
