#pragma once
// The Vulkan context a timed benchmark case runs on: validation off (the layers would be timed
// too), and no silent CPU fallback, since a Vulkan case without a device has nothing to measure.
#include <memory>

#include "relight/vk/context.h"

namespace relight::bench {

/// Throws relight::Error ("no Vulkan device: <why>") when there is none.
[[nodiscard]] std::unique_ptr<vk::VulkanContext> timing_vulkan();

}  // namespace relight::bench
