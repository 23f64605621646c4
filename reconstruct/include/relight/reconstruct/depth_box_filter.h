#pragma once
// 3x3 box filter over a DepthMap that ignores missing depth: relight's first CPU+Vulkan kernel.
//
// Definition (both backends compute exactly this):
//   out(r, c) = 0                                   if depth(r, c) is invalid (!is_valid_depth)
//   out(r, c) = mean of the valid depth values in the 3x3 window centred on (r, c), clipped at
//               the image border (so 4 pixels at a corner, 6 on an edge), centre included.
// Invalid pixels are never filled in (the filter smooths, it does not inpaint), and because the
// centre is valid the mean always has at least one term. Sums run row-major over the window in
// float, then one division, so the Vulkan result matches the CPU reference to float rounding.
//
// Three ways to run it:
//   - depth_box_filter(depth)                 : the CPU reference (plain, serial; also the fast
//                                               path on lavapipe machines, see docs/platform.md)
//   - DepthBoxFilterVk(context).run(depth)    : Vulkan without the frame graph
//   - DepthBoxFilterCpuStage / DepthBoxFilterVkStage, or make_depth_box_filter_stage(backend, ...):
//     frame-graph stages reading a DepthMap buffer ("depth") and writing one ("depth_smoothed").
// This header includes no Vulkan headers.
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "relight/core/buffers.h"
#include "relight/core/frame_graph.h"
#include "relight/core/image.h"

namespace relight::vk {
class VulkanBuffer;
class VulkanContext;
}  // namespace relight::vk

namespace relight::reconstruct {

/// CPU reference. Writes `smoothed` (resized to depth's shape); `smoothed` must not be `depth`.
void depth_box_filter(const DepthMap& depth, DepthMap& smoothed);
[[nodiscard]] DepthMap depth_box_filter(const DepthMap& depth);

/// The Vulkan implementation. Holds the compute pipeline, so create it once and reuse it.
class DepthBoxFilterVk {
 public:
  explicit DepthBoxFilterVk(vk::VulkanContext& context);
  ~DepthBoxFilterVk();
  DepthBoxFilterVk(const DepthBoxFilterVk&) = delete;
  DepthBoxFilterVk& operator=(const DepthBoxFilterVk&) = delete;

  /// Filters `depth` (width*height floats, row-major) into `smoothed` (same size) on the GPU,
  /// waiting for completion. Returns the GPU time in ms when the device has timestamps.
  std::optional<double> run(const vk::VulkanBuffer& depth, vk::VulkanBuffer& smoothed, int width, int height);
  /// Convenience: uploads `depth`, filters, downloads the result (through context.transfer()).
  [[nodiscard]] DepthMap run(const DepthMap& depth);
  /// GPU ms of the last run(), if timestamps are supported.
  [[nodiscard]] std::optional<double> last_gpu_ms() const { return last_gpu_ms_; }

 private:
  struct Pipeline;
  vk::VulkanContext& context_;
  std::unique_ptr<Pipeline> pipeline_;
  std::optional<double> last_gpu_ms_;
};

/// Buffer names of the box-filter stages.
struct DepthBoxFilterBuffers {
  BufferName<DepthMap> input = kDepth;
  BufferName<DepthMap> output = kDepthSmoothed;
};

/// CPU stage: reads DepthMap `input`, writes DepthMap `output`.
class DepthBoxFilterCpuStage final : public Stage {
 public:
  explicit DepthBoxFilterCpuStage(DepthBoxFilterBuffers buffers = {}) : buffers_(buffers) {}
  [[nodiscard]] std::string name() const override { return "depth_box_filter"; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;

 private:
  DepthBoxFilterBuffers buffers_;
  Read<DepthMap> input_;
  Write<DepthMap> output_;
};

/// Vulkan stage: same buffers; the graph uploads `input` if needed and downloads `output` only
/// when a CPU stage or the caller reads it. Reports GPU time (timestamp queries) to the graph.
/// The graph must have been built with `&context.transfer()` as its DeviceTransfer.
class DepthBoxFilterVkStage final : public Stage {
 public:
  explicit DepthBoxFilterVkStage(vk::VulkanContext& context, DepthBoxFilterBuffers buffers = {});
  [[nodiscard]] std::string name() const override { return "depth_box_filter"; }
  [[nodiscard]] Backend backend() const override { return Backend::Vulkan; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;

 private:
  DepthBoxFilterVk filter_;
  DepthBoxFilterBuffers buffers_;
  Read<DepthMap> input_;
  Write<DepthMap> output_;
};

/// The stage for `backend` (core/stage_backend.h; pick it with vk::choose_backend(StageKind::PerPixel,
/// ...)). Backend::Vulkan requires a non-null `context` (else relight::LogicError).
[[nodiscard]] std::unique_ptr<Stage> make_depth_box_filter_stage(Backend backend, vk::VulkanContext* context,
                                                                 DepthBoxFilterBuffers buffers = {});

}  // namespace relight::reconstruct
