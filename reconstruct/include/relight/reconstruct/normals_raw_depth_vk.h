#pragma once
// Method 1 (normals_raw_depth.h, Knecht 2013 §4.3.2) with every per-pixel pass on Vulkan:
//   1. positions φ⁻¹(depth) and stride-s cross-product normals (eq. 4.4–4.6; CrossNormalsVk),
//   2. pass 2's temporal blend with the history (eq. 4.7–4.8; shaders/normals_blend.comp),
//   3. hole filling from the 4-neighbours (shaders/normals_fill_holes.comp).
// Pass 1 (the half-resolution mean/curvature pyramid, eq. 4.1–4.3) runs on the CPU
// (normals_history_pyramid) and is uploaded, with the previous frame's positions.
//
// Reads:  depth, intrinsics, this frame's camera_to_world, the previous frame's NormalsHistory
//         (null on the first frame; ignored when its shape differs), NormalsRawDepthOptions
//         (threads only for the CPU pyramid).
// Writes: positions and normals exactly as normals_raw_depth defines them, to float rounding.
// This header includes no Vulkan headers.
#include <memory>
#include <optional>
#include <string>

#include "relight/core/camera.h"
#include "relight/core/frame_graph.h"
#include "relight/core/image.h"
#include "relight/core/pose.h"
#include "relight/reconstruct/cross_normals_vk.h"
#include "relight/reconstruct/normals_raw_depth.h"

namespace relight {

/// Holds the pipelines: create once, reuse every frame.
class NormalsRawDepthVk {
 public:
  explicit NormalsRawDepthVk(vk::VulkanContext& context);
  ~NormalsRawDepthVk();
  NormalsRawDepthVk(const NormalsRawDepthVk&) = delete;
  NormalsRawDepthVk& operator=(const NormalsRawDepthVk&) = delete;

  /// One frame (uploads, three dispatches, downloads). Resizes the outputs.
  void run(const DepthMap& depth, const PinholeIntrinsics& intrinsics, const Pose& camera_to_world,
           const NormalsHistory* previous, const NormalsRawDepthOptions& options, PositionMap& positions,
           NormalMap& normals);
  /// Sum of the GPU times of the last run()'s dispatches, if the device has timestamps.
  [[nodiscard]] std::optional<double> last_gpu_ms() const { return last_gpu_ms_; }

 private:
  struct Pipelines;
  struct Scratch;
  vk::VulkanContext& context_;
  CrossNormalsVk cross_;
  std::unique_ptr<Pipelines> pipelines_;
  std::unique_ptr<Scratch> scratch_;
  std::optional<double> last_gpu_ms_;
};

/// Frame-graph stage of method 1 on Vulkan, a drop-in for NormalsRawDepthCpuStage (same name and
/// buffers for either NormalsDepthInput: reads DepthMap "depth" or "depth_filtered", FrameInfo
/// "frame" and the previous frame's "normals", "positions" and "frame"; writes NormalMap
/// "normals" and PositionMap "positions").
/// It works on the graph's host buffers and does its own uploads and downloads, because the
/// graph hands previous-frame buffers to stages on the host only and pass 1 runs on the CPU
/// anyway; so backend() is Cpu in the graph's sense, while the GPU time of the dispatches is
/// reported to the graph's timing table.
class NormalsRawDepthVkStage final : public NormalsRawDepthStageBase {
 public:
  explicit NormalsRawDepthVkStage(vk::VulkanContext& context, NormalsRawDepthOptions options = {},
                                  NormalsDepthInput input = NormalsDepthInput::Raw)
      : NormalsRawDepthStageBase(options, input), method_(context) {}

 private:
  void estimate(StageContext& context, const DepthMap& depth, const PinholeIntrinsics& intrinsics,
                const Pose& camera_to_world, const NormalsHistory* previous, PositionMap& positions,
                NormalMap& normals) override;
  NormalsRawDepthVk method_;
};

}  // namespace relight
