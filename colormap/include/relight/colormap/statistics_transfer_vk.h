#pragma once
// Vulkan version of the statistics-based mapping (definition in statistics_transfer.h).
// Two compute passes:
//   1. shaders/colormap_statistics.comp: per pixel the valid test, f(TM(L_r)) and f(L_cam);
//      each work group of RELIGHT_COLORMAP_STATS_GROUP pixels reduces its 13 sums (count, sum and
//      sum of squares of 3 channels, source and target) in shared memory and writes them as one
//      row of a partial-sums buffer. The host adds the rows in double: the statistics are exact
//      means and variances over all valid pixels (no mip-map approximation), equal to the CPU
//      reference to float rounding of the per-group sums.
//   2. shaders/colormap_statistics_transfer.comp: delta_L = tau_st(L_rv) - tau_st(L_r) per pixel.
// The camera image is read as packed bytes, so width * height must be a multiple of 4 (every
// camera resolution is); anything else is a relight::Error.
// This header includes no Vulkan headers.
#include <memory>
#include <optional>

#include "relight/colormap/statistics_transfer.h"

namespace relight::vk {
class VulkanBuffer;
class VulkanContext;
}  // namespace relight::vk

namespace relight::colormap {

class StatisticsColorMapVk {
 public:
  explicit StatisticsColorMapVk(vk::VulkanContext& context);
  ~StatisticsColorMapVk();
  StatisticsColorMapVk(const StatisticsColorMapVk&) = delete;
  StatisticsColorMapVk& operator=(const StatisticsColorMapVk&) = delete;

  /// Pass 1 on device buffers (Float3 radiance, Rgb8 camera), sums finished on the host.
  [[nodiscard]] LabSums reduce(const vk::VulkanBuffer& real, const vk::VulkanBuffer& real_virtual,
                               const vk::VulkanBuffer& camera, int width, int height);
  /// Pass 2: writes delta (width * height Float3).
  void transfer(const vk::VulkanBuffer& real, const vk::VulkanBuffer& real_virtual, const ReinhardTransfer& transfer,
                vk::VulkanBuffer& delta, int width, int height);
  /// Both passes; returns the transfer used. GPU time of both passes in last_gpu_ms().
  ReinhardTransfer run(const vk::VulkanBuffer& real, const vk::VulkanBuffer& real_virtual,
                       const vk::VulkanBuffer& camera, vk::VulkanBuffer& delta, int width, int height);
  /// Convenience: uploads, runs, downloads `delta`.
  ReinhardTransfer run(const RadianceImage& real, const RadianceImage& real_virtual, const ColorImage& camera,
                       RadianceImage& delta);

  [[nodiscard]] const ToneMap& tone_map() const { return tm_; }
  void set_tone_map(const ToneMap& tm) { tm_ = tm; }
  [[nodiscard]] std::optional<double> last_gpu_ms() const { return last_gpu_ms_; }

 private:
  struct Pipelines;
  vk::VulkanContext& context_;
  std::unique_ptr<Pipelines> pipelines_;
  ToneMap tm_;
  std::optional<double> last_gpu_ms_;
};

}  // namespace relight::colormap
