#pragma once
// Error handling for Vulkan calls: RELIGHT_VK_CHECK(call) throws relight::vk::VulkanError (a
// relight::Error, so the CLI prints it as one line) naming the call, the VkResult and the source
// location. Nothing in the Vulkan layer calls exit().
#include <vulkan/vulkan.h>

#include <string>

#include "relight/core/error.h"

namespace relight::vk {

/// A Vulkan call failed. result() is the VkResult it returned (VK_ERROR_DEVICE_LOST, ...).
class VulkanError : public Error {
 public:
  VulkanError(VkResult result, const std::string& message) : Error(message), result_(result) {}
  [[nodiscard]] VkResult result() const { return result_; }

 private:
  VkResult result_;
};

/// "VK_ERROR_OUT_OF_DEVICE_MEMORY" etc.; "VkResult(<n>)" for values this build does not know.
[[nodiscard]] std::string result_name(VkResult result);

/// Throws VulkanError "<call> failed with <VK_...> at <file>:<line>".
[[noreturn]] void throw_vulkan_error(VkResult result, const char* call, const char* file, int line);

}  // namespace relight::vk

/// Evaluates a Vulkan call once; any result other than VK_SUCCESS throws VulkanError. Calls that
/// may legitimately return VK_INCOMPLETE/VK_TIMEOUT/VK_NOT_READY check their result by hand.
#define RELIGHT_VK_CHECK(call)                                                      \
  do {                                                                              \
    const VkResult relight_vk_result_ = (call);                                     \
    if (relight_vk_result_ != VK_SUCCESS) {                                         \
      ::relight::vk::throw_vulkan_error(relight_vk_result_, #call, __FILE__, __LINE__); \
    }                                                                               \
  } while (false)
