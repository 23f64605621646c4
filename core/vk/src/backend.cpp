#include "relight/vk/backend.h"

#include "relight/core/error.h"
#include "relight/vk/context.h"

namespace relight::vk {

Backend choose_backend(StageKind kind, const VulkanContext* context, BackendPolicy policy) {
  switch (policy) {
    case BackendPolicy::ForceCpu: return Backend::Cpu;
    case BackendPolicy::ForceVulkan:
      if (!context) throw Error("the Vulkan backend was forced but no Vulkan device is available");
      return Backend::Vulkan;
    case BackendPolicy::Auto: break;
  }
  if (!context) return Backend::Cpu;
  if (kind == StageKind::PerPixel && context->is_cpu_device()) return Backend::Cpu;
  return Backend::Vulkan;
}

std::optional<BackendPolicy> parse_backend_policy(std::string_view text) {
  if (text == "auto") return BackendPolicy::Auto;
  if (text == "cpu") return BackendPolicy::ForceCpu;
  if (text == "vulkan") return BackendPolicy::ForceVulkan;
  return std::nullopt;
}

const char* to_string(BackendPolicy policy) {
  switch (policy) {
    case BackendPolicy::Auto: return "auto";
    case BackendPolicy::ForceCpu: return "cpu";
    case BackendPolicy::ForceVulkan: return "vulkan";
  }
  return "auto";
}

}  // namespace relight::vk
