#pragma once
// Validation-layer plumbing. When validation is on, VulkanContext installs a debug messenger that
// prints every warning/error to stderr and counts them in a ValidationLog, so tests can assert
// that a run produced zero validation errors (a message alone would scroll past unnoticed).
// The log is shared (std::shared_ptr) so that it outlives the context: errors reported while the
// device is destroyed (leaked objects) are still counted.
#include <vulkan/vulkan.h>

#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

namespace relight::vk {

class ValidationLog {
 public:
  [[nodiscard]] int errors() const { return errors_.load(); }
  [[nodiscard]] int warnings() const { return warnings_.load(); }
  /// The last few error messages (at most 16), oldest first, for test failure output.
  [[nodiscard]] std::vector<std::string> recent_errors() const;
  /// All recent errors as one string, one per line.
  [[nodiscard]] std::string summary() const;

  /// Called by the messenger; public so that tests can feed it.
  void record(VkDebugUtilsMessageSeverityFlagBitsEXT severity, const char* message);

  /// While held, messages are kept, neither printed nor counted; release(true) records them as
  /// they came, release(false) drops them. VulkanContext holds the messages of vkCreateInstance:
  /// when it fails (no driver at all) the loader's own lines would follow relight's one-line
  /// note about it, which already says what went wrong.
  void hold();
  void release(bool record_held);

 private:
  void record_now(VkDebugUtilsMessageSeverityFlagBitsEXT severity, const std::string& message);

  std::atomic<int> errors_{0};
  std::atomic<int> warnings_{0};
  mutable std::mutex mutex_;
  std::vector<std::string> recent_;
  std::mutex held_mutex_;
  bool holding_ = false;
  std::vector<std::pair<VkDebugUtilsMessageSeverityFlagBitsEXT, std::string>> held_;
};

/// Owns a VkDebugUtilsMessengerEXT that forwards warnings and errors to a ValidationLog. The
/// messenger's functions come from vkGetInstanceProcAddr (VK_EXT_debug_utils is an extension).
class DebugMessenger {
 public:
  DebugMessenger() = default;
  DebugMessenger(VkInstance instance, std::shared_ptr<ValidationLog> log);
  ~DebugMessenger();
  DebugMessenger(const DebugMessenger&) = delete;
  DebugMessenger& operator=(const DebugMessenger&) = delete;
  DebugMessenger(DebugMessenger&& other) noexcept;
  DebugMessenger& operator=(DebugMessenger&& other) noexcept;

  /// The create-info to chain into VkInstanceCreateInfo::pNext so that vkCreateInstance and
  /// vkDestroyInstance themselves are validated. `log` must outlive the instance.
  [[nodiscard]] static VkDebugUtilsMessengerCreateInfoEXT create_info(ValidationLog* log);

 private:
  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  PFN_vkDestroyDebugUtilsMessengerEXT destroy_ = nullptr;
  std::shared_ptr<ValidationLog> log_;
};

}  // namespace relight::vk
