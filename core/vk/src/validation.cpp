#include "relight/vk/validation.h"

#include <iostream>
#include <utility>

#include "relight/vk/check.h"

namespace relight::vk {

namespace {
constexpr std::size_t kRecentErrors = 16;

VKAPI_ATTR VkBool32 VKAPI_CALL on_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                          VkDebugUtilsMessageTypeFlagsEXT /*types*/,
                                          const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  static_cast<ValidationLog*>(user)->record(severity, data && data->pMessage ? data->pMessage : "(no message)");
  return VK_FALSE;  // never abort the call: the caller sees the error through the log instead
}
}  // namespace

void ValidationLog::record(VkDebugUtilsMessageSeverityFlagBitsEXT severity, const char* message) {
  {
    std::lock_guard lock(held_mutex_);
    if (holding_) {
      held_.emplace_back(severity, message);
      return;
    }
  }
  record_now(severity, message);
}

void ValidationLog::hold() {
  std::lock_guard lock(held_mutex_);
  holding_ = true;
}

void ValidationLog::release(bool record_held) {
  std::vector<std::pair<VkDebugUtilsMessageSeverityFlagBitsEXT, std::string>> held;
  {
    std::lock_guard lock(held_mutex_);
    holding_ = false;
    held.swap(held_);
  }
  if (!record_held) return;
  for (const auto& [severity, message] : held) record_now(severity, message);
}

void ValidationLog::record_now(VkDebugUtilsMessageSeverityFlagBitsEXT severity, const std::string& message) {
  const bool error = severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  std::cerr << "relight vulkan " << (error ? "validation error: " : "validation warning: ") << message << '\n';
  if (!error) {
    ++warnings_;
    return;
  }
  ++errors_;
  std::lock_guard lock(mutex_);
  if (recent_.size() == kRecentErrors) recent_.erase(recent_.begin());
  recent_.emplace_back(message);
}

std::vector<std::string> ValidationLog::recent_errors() const {
  std::lock_guard lock(mutex_);
  return recent_;
}

std::string ValidationLog::summary() const {
  std::string text;
  for (const auto& message : recent_errors()) text += message + '\n';
  return text;
}

VkDebugUtilsMessengerCreateInfoEXT DebugMessenger::create_info(ValidationLog* log) {
  VkDebugUtilsMessengerCreateInfoEXT info{};
  info.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
  info.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                     VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  info.pfnUserCallback = on_message;
  info.pUserData = log;
  return info;
}

DebugMessenger::DebugMessenger(VkInstance instance, std::shared_ptr<ValidationLog> log)
    : instance_(instance), log_(std::move(log)) {
  auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
      vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT"));
  destroy_ = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
      vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
  if (!create || !destroy_) throw_vulkan_error(VK_ERROR_EXTENSION_NOT_PRESENT, "vkGetInstanceProcAddr(debug utils)", __FILE__, __LINE__);
  const auto info = create_info(log_.get());
  RELIGHT_VK_CHECK(create(instance, &info, nullptr, &messenger_));
}

DebugMessenger::~DebugMessenger() {
  if (messenger_ != VK_NULL_HANDLE) destroy_(instance_, messenger_, nullptr);
}

DebugMessenger::DebugMessenger(DebugMessenger&& other) noexcept
    : instance_(other.instance_),
      messenger_(std::exchange(other.messenger_, VK_NULL_HANDLE)),
      destroy_(other.destroy_),
      log_(std::move(other.log_)) {}

DebugMessenger& DebugMessenger::operator=(DebugMessenger&& other) noexcept {
  std::swap(instance_, other.instance_);
  std::swap(messenger_, other.messenger_);
  std::swap(destroy_, other.destroy_);
  std::swap(log_, other.log_);
  return *this;
}

}  // namespace relight::vk
