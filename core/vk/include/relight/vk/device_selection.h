#pragma once
// Which physical device the Vulkan context uses. Kept apart from the context (and free of Vulkan
// headers) so that the rule can be tested with made-up device lists on a machine without a GPU.
//
// Rule: a selector (VulkanOptions::device, else the environment variable RELIGHT_VK_DEVICE) picks
// a device by index ("1"), by type ("discrete", "integrated", "virtual", "cpu") or by a
// case-insensitive substring of its name ("llvmpipe", "RTX"). Without a selector the best usable
// device wins: discrete > integrated > virtual > CPU (lavapipe) > other; ties go to the lower index.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace relight::vk {

enum class DeviceType { Discrete, Integrated, Virtual, Cpu, Other };
[[nodiscard]] const char* to_string(DeviceType type);

struct DeviceInfo {
  std::string name;                 ///< VkPhysicalDeviceProperties::deviceName
  DeviceType type = DeviceType::Other;
  std::uint32_t api_version = 0;    ///< VK_MAKE_API_VERSION-encoded
  bool usable = true;               ///< false: lacks what relight needs (Vulkan 1.1, a compute queue)
  std::string unusable_reason;      ///< why, when !usable
};

/// Index into `devices` of the device to use. Throws relight::Error when nothing usable matches;
/// the message lists every device with its index, type and (if unusable) the reason.
[[nodiscard]] std::size_t choose_physical_device(const std::vector<DeviceInfo>& devices, std::string_view selector);

/// "0: llvmpipe (LLVM 15.0.6, 256 bits) [cpu]" lines, for messages and `--list-devices`.
[[nodiscard]] std::string describe_devices(const std::vector<DeviceInfo>& devices);

}  // namespace relight::vk
