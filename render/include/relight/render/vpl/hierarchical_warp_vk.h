#pragma once
// Hierarchical warping on Vulkan (definition and CPU reference in hierarchical_warp.h): the sum
// pyramid in one compute dispatch per three levels (shaders/warp_pyramid.comp), then one
// invocation per point descends it (shaders/warp_descend.comp). Same texels as the CPU for the same points; the
// probabilities are importance / total with the device's division (within a few ulps).
//
// Reads:  importance (size * size floats, row-major, >= 0 and finite: the caller's contract on
//         device buffers, checked by the host convenience), points (count x (u, v) floats).
// Writes: an internal pyramid buffer, and samples (count x 3 words: x, y, probability float bits;
//         x = y = 0xffffffff and probability 0 for every point when the map's total is 0).
// This header includes no Vulkan headers.
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "relight/render/vpl/hierarchical_warp.h"

namespace relight::vk {
class VulkanBuffer;
class VulkanContext;
}  // namespace relight::vk

namespace relight::render {

/// Holds the pipelines and the pyramid buffer: create once, reuse every frame.
class HierarchicalWarpVk {
 public:
  explicit HierarchicalWarpVk(vk::VulkanContext& context);
  ~HierarchicalWarpVk();
  HierarchicalWarpVk(const HierarchicalWarpVk&) = delete;
  HierarchicalWarpVk& operator=(const HierarchicalWarpVk&) = delete;

  /// Device buffers: `importance` >= size^2 floats, `points` >= 2 * count floats, `samples` >=
  /// 3 * count words. Waits for completion; returns the GPU ms when the device has timestamps.
  /// Throws LogicError on a size that is not a power of two in [1, ImportancePyramid::kMaxSize]
  /// or buffers that are too small.
  std::optional<double> run(const vk::VulkanBuffer& importance, int size, const vk::VulkanBuffer& points,
                            std::uint32_t count, vk::VulkanBuffer& samples);

  /// Convenience: checks the map like ImportancePyramid (Error on bad input), uploads, runs and
  /// downloads. Empty when the map's total is 0, like warp_points.
  std::vector<WarpedTexel> warp(std::span<const float> importance, int size, std::span<const WarpPoint> points);

  /// The pyramid of the last run, downloaded (level 0 first, as ImportancePyramid::data()).
  [[nodiscard]] std::vector<float> download_pyramid() const;

 private:
  struct Pipelines;
  vk::VulkanContext& context_;
  std::unique_ptr<Pipelines> pipelines_;
};

}  // namespace relight::render
