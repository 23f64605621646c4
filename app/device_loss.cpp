#include "device_loss.h"

#include <cstdlib>

#include "relight/core/error.h"
#include "relight/vk/check.h"
#include "relight/vk/context.h"

namespace relight::app {

DeviceLossHook::DeviceLossHook(vk::VulkanContext* context) : context_(context) {
  const char* text = std::getenv("RELIGHT_TEST_DEVICE_LOST_AT_FRAME");
  if (text == nullptr || *text == '\0') return;
  char* end = nullptr;
  const long long frame = std::strtoll(text, &end, 10);
  if (*end != '\0' || frame < 0) {
    throw Error(std::string("RELIGHT_TEST_DEVICE_LOST_AT_FRAME=") + text + " is not a frame number");
  }
  lost_at_ = frame;
}

void DeviceLossHook::before_frame(std::int64_t frame) {
  if (context_ != nullptr && lost_at_ && frame == *lost_at_) context_->simulate_device_loss();
}

std::optional<std::string> device_loss_message(const std::exception& error, std::int64_t frame) {
  const auto* vulkan = dynamic_cast<const vk::VulkanError*>(&error);
  if (vulkan == nullptr || vulkan->result() != VK_ERROR_DEVICE_LOST) return std::nullopt;
  const std::string held = frame == 0   ? "no frame"
                           : frame == 1 ? "frame 0"
                                        : "the " + std::to_string(frame) + " frames before it";
  return "the Vulkan device was lost during frame " + std::to_string(frame) + " (" + vulkan->what() +
         "); the outputs hold " + held + "; --cpu runs without the GPU";
}

}  // namespace relight::app
