#pragma once
// Method 1 (normals_raw_depth.h, Knecht 2013 §4.3.2) with every per-pixel pass on Vulkan:
//   1. positions φ⁻¹(depth) and stride-s cross-product normals (eq. 4.4–4.6; CrossNormalsVk),
//   2. pass 2's temporal blend with the history (eq. 4.7–4.8; shaders/normals_blend.comp),
//   3. hole filling from the 4-neighbours (shaders/normals_fill_holes.comp).
// Pass 1 (the half-resolution mean/curvature pyramid, eq. 4.1–4.3) runs on the CPU
// (normals_history_pyramid) from the previous frame's normals on the host, and is uploaded;
// the previous frame's positions stay on the device.
//
// Reads:  depth, intrinsics, this frame's camera_to_world, the previous frame's normals,
//         positions and pose (none on the first frame; ignored when their shape differs),
//         NormalsRawDepthOptions (threads only for the CPU pyramid).
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

namespace relight::reconstruct {

/// The previous frame as the device version of method 1 reads it: normals on the host (pass 1's
/// pyramid is built on the CPU), positions on the device (`positions` >= width*height Float3).
struct NormalsDeviceHistory {
  const NormalMap& normals;
  const vk::VulkanBuffer& positions;
  Pose camera_to_world;
};

/// Holds the pipelines: create once, reuse every frame.
class NormalsRawDepthVk {
 public:
  explicit NormalsRawDepthVk(vk::VulkanContext& context);
  ~NormalsRawDepthVk();
  NormalsRawDepthVk(const NormalsRawDepthVk&) = delete;
  NormalsRawDepthVk& operator=(const NormalsRawDepthVk&) = delete;

  /// One frame on device buffers: `depth` >= width*height floats, `positions` and `normals` >=
  /// width*height Float3. `previous` may be null (first frame) and is ignored when its normals
  /// are not width x height. Waits for completion; returns the GPU time when the device has
  /// timestamps. Scratch buffers are kept across calls (no allocation while the size holds).
  std::optional<double> run(const vk::VulkanBuffer& depth, int width, int height, const PinholeIntrinsics& intrinsics,
                            const Pose& camera_to_world, const NormalsDeviceHistory* previous,
                            const NormalsRawDepthOptions& options, vk::VulkanBuffer& positions,
                            vk::VulkanBuffer& normals);
  /// Convenience on host maps (tests, benchmarks): uploads, runs, downloads. Resizes the outputs.
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
/// It works on the graph's device buffers (backend() Vulkan): depth, this frame's outputs and
/// the previous frame's positions on the device (the graph double-buffers them), the previous
/// normals on the host for pass 1. It reports the GPU time of its dispatches.
class NormalsRawDepthVkStage final : public NormalsRawDepthStageBase {
 public:
  explicit NormalsRawDepthVkStage(vk::VulkanContext& context, NormalsRawDepthOptions options = {},
                                  NormalsDepthInput input = NormalsDepthInput::Raw)
      : NormalsRawDepthStageBase(options, input), method_(context) {}
  [[nodiscard]] Backend backend() const override { return Backend::Vulkan; }
  void run(StageContext& context) override;

 private:
  NormalsRawDepthVk method_;
};

}  // namespace relight::reconstruct
