#pragma once
// The Vulkan device lost in the middle of a run (a driver reset, a GPU fault, an unplugged eGPU):
// replay and live stop at that frame, finalise what the frames before it produced (frames, video,
// report, trajectory) and fail with one line that names the frame and says that --cpu runs without
// the GPU. Not a switch to the CPU path for the rest of the run: the graph's stages are chosen
// when it is built and keep device-resident state and history, so a CPU graph built mid-run would
// restart the tracking, the temporal smoothing and the video; the frames before the loss are right,
// which is what a finalised stop keeps.
//
// RELIGHT_TEST_DEVICE_LOST_AT_FRAME=k (the robustness rows): the device reports itself lost from
// frame k on (VulkanContext::simulate_device_loss), as no driver can be made to lose it on demand.
#include <cstdint>
#include <exception>
#include <optional>
#include <string>

namespace relight::vk {
class VulkanContext;
}

namespace relight::app {

class DeviceLossHook {
 public:
  /// Reads RELIGHT_TEST_DEVICE_LOST_AT_FRAME; `context` may be null (nothing runs on Vulkan).
  /// Throws relight::Error when the variable is not a frame number.
  explicit DeviceLossHook(vk::VulkanContext* context);
  /// Called before frame `frame` (0-based) runs.
  void before_frame(std::int64_t frame);

 private:
  vk::VulkanContext* context_;
  std::optional<std::int64_t> lost_at_;
};

/// The one line for a run stopped by `error` while frame `frame` ran, when `error` is a lost
/// Vulkan device; nullopt for any other error.
[[nodiscard]] std::optional<std::string> device_loss_message(const std::exception& error, std::int64_t frame);

}  // namespace relight::app
