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

}  // namespace relight::vk
