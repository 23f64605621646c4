#pragma once
// GpuTimer: GPU time between two points of a command buffer, from timestamp queries, so that a
// Vulkan stage can report device milliseconds (StageContext::report_device_ms) next to its wall
// time. Ticks are converted with VkPhysicalDeviceLimits::timestampPeriod (ns per tick).
//
//   GpuTimer timer(context);
//   context.submit([&](VkCommandBuffer cmd) { timer.start(cmd); ...dispatch...; timer.stop(cmd); });
//   if (auto ms = timer.elapsed_ms()) stage_context.report_device_ms(*ms);
#include <vulkan/vulkan.h>

#include <cstdint>
#include <optional>

#include "relight/vk/handles.h"

namespace relight::vk {

class VulkanContext;

class GpuTimer {
 public:
  explicit GpuTimer(const VulkanContext& context);

  /// Records "reset the two queries; write the start timestamp" (no-op without timestamps).
  void start(VkCommandBuffer cmd);
  /// Records the end timestamp once all earlier commands have finished.
  void stop(VkCommandBuffer cmd);
  /// Milliseconds between start and stop, once that command buffer has completed; empty when
  /// timestamps are unsupported, start/stop were not both recorded, or results are not ready.
  [[nodiscard]] std::optional<double> elapsed_ms() const;

 private:
  UniqueQueryPool pool_;
  double period_ns_ = 0.0;
  std::uint64_t mask_ = 0;
  bool started_ = false;
  bool stopped_ = false;
};

}  // namespace relight::vk
