#pragma once
// Vulkan version of positions_from_depth + normals_from_positions (normals_from_positions.h):
// method 1's per-frame normal estimation (Knecht 2013, §4.3.2, eq. 4.4–4.6 with stride s) and
// method 2's normal stage (s = 1), in one compute dispatch (shaders/cross_normals.comp).
//
// Reads:  depth (width*height floats, row-major metres; invalid = not finite or <= 0),
//         intrinsics and CrossNormalOptions::stride / max_jump_rel (threads is ignored).
// Writes: positions V = φ⁻¹(depth) (eq. 4.9; (0,0,0) without depth) and normals
//         N = normalize(d_col × d_row) oriented towards the camera, with the CPU reference's
//         forward/backward difference and discontinuity rules ((0,0,0) = no normal).
// Positions equal the CPU's bit for bit (no fused multiply-add); normals agree to float
// rounding of the cross product, length and division.
//
// Method 1's temporal blend (eq. 4.7–4.8) follows in NormalsRawDepthVk (normals_raw_depth_vk.h),
// or on the CPU with normals_raw_depth_blend (normals_raw_depth.h) on the downloaded maps.
// This header includes no Vulkan headers.
#include <memory>
#include <optional>

#include <string>

#include "relight/core/camera.h"
#include "relight/core/frame_graph.h"
#include "relight/core/image.h"
#include "relight/core/rgbd_frame.h"
#include "relight/reconstruct/normals_from_positions.h"

namespace relight::vk {
class VulkanBuffer;
class VulkanContext;
}  // namespace relight::vk

namespace relight::reconstruct {

/// Holds the compute pipeline: create once, reuse every frame.
class CrossNormalsVk {
 public:
  explicit CrossNormalsVk(vk::VulkanContext& context);
  ~CrossNormalsVk();
  CrossNormalsVk(const CrossNormalsVk&) = delete;
  CrossNormalsVk& operator=(const CrossNormalsVk&) = delete;

  /// Device buffers: `depth` >= width*height floats, `positions` and `normals` >= width*height*3
  /// floats (Float3, tightly packed like PositionMap/NormalMap). Waits for completion; returns
  /// the GPU time in ms when the device has timestamps. Throws LogicError on a bad stride or
  /// buffers that are too small.
  std::optional<double> run(const vk::VulkanBuffer& depth, vk::VulkanBuffer& positions, vk::VulkanBuffer& normals,
                            int width, int height, const PinholeIntrinsics& intrinsics,
                            const CrossNormalOptions& options);
  /// Convenience: uploads `depth`, runs, downloads into `positions` and `normals` (resized).
  void run(const DepthMap& depth, const PinholeIntrinsics& intrinsics, const CrossNormalOptions& options,
           PositionMap& positions, NormalMap& normals);
  /// GPU ms of the last run(), if timestamps are supported.
  [[nodiscard]] std::optional<double> last_gpu_ms() const { return last_gpu_ms_; }

 private:
  struct Pipeline;
  vk::VulkanContext& context_;
  std::unique_ptr<Pipeline> pipeline_;
  std::optional<double> last_gpu_ms_;
};

/// Method 2's normal stage on Vulkan, a drop-in for NormalsFromPositionsCpuStage (same name and
/// buffers: reads DepthMap "depth_filtered" and FrameInfo "frame", writes PositionMap "positions"
/// and NormalMap "normals"), on the graph's device buffers (backend() Vulkan): the graph moves
/// data only where the other side needs it.
class NormalsFromPositionsVkStage final : public Stage {
 public:
  explicit NormalsFromPositionsVkStage(vk::VulkanContext& context, CrossNormalOptions options = {})
      : cross_(context), options_(options) {}
  [[nodiscard]] std::string name() const override { return "normals_from_positions"; }
  [[nodiscard]] Backend backend() const override { return Backend::Vulkan; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;

 private:
  CrossNormalsVk cross_;
  CrossNormalOptions options_;
  Read<DepthMap> depth_;
  Read<FrameInfo> frame_;
  Write<PositionMap> positions_;
  Write<NormalMap> normals_;
};

}  // namespace relight::reconstruct
