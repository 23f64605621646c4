#include "vulkan_timing.h"

#include <string>

#include "relight/core/error.h"

namespace relight::bench {

std::unique_ptr<vk::VulkanContext> timing_vulkan() {
  std::string why;
  auto context = vk::try_create_vulkan({.validation = vk::Validation::Off}, &why);
  if (!context) throw Error("no Vulkan device: " + why);
  return context;
}

}  // namespace relight::bench
