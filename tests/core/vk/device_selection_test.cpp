// Device choice and backend policy: pure rules, tested with made-up device lists (no GPU needed).
#include "relight/vk/device_selection.h"

#include <gtest/gtest.h>

#include "relight/core/error.h"
#include "relight/vk/backend.h"

namespace relight::vk {
namespace {

DeviceInfo device(std::string name, DeviceType type, bool usable = true) {
  DeviceInfo info;
  info.name = std::move(name);
  info.type = type;
  info.usable = usable;
  if (!usable) info.unusable_reason = "Vulkan 1.1 required";
  return info;
}

const std::vector<DeviceInfo> kMachine = {
    device("llvmpipe (LLVM 15.0.6, 256 bits)", DeviceType::Cpu),
    device("Intel(R) UHD Graphics 630", DeviceType::Integrated),
    device("NVIDIA GeForce RTX 3080", DeviceType::Discrete),
    device("Virtio GPU", DeviceType::Virtual),
};

TEST(DeviceSelection, PrefersDiscreteThenIntegratedThenVirtualThenCpu) {
  EXPECT_EQ(choose_physical_device(kMachine, ""), 2u);
  EXPECT_EQ(choose_physical_device({kMachine[0], kMachine[1], kMachine[3]}, ""), 1u);
  EXPECT_EQ(choose_physical_device({kMachine[0], kMachine[3]}, ""), 1u);
  EXPECT_EQ(choose_physical_device({kMachine[0]}, ""), 0u);
}

TEST(DeviceSelection, SelectorByIndexTypeOrNameSubstring) {
  EXPECT_EQ(choose_physical_device(kMachine, "0"), 0u);
  EXPECT_EQ(choose_physical_device(kMachine, "3"), 3u);
  EXPECT_EQ(choose_physical_device(kMachine, "cpu"), 0u);
  EXPECT_EQ(choose_physical_device(kMachine, "integrated"), 1u);
  EXPECT_EQ(choose_physical_device(kMachine, "LLVMpipe"), 0u);
  EXPECT_EQ(choose_physical_device(kMachine, "rtx"), 2u);
}

TEST(DeviceSelection, UnusableDevicesAreSkipped) {
  const std::vector<DeviceInfo> devices = {device("old discrete", DeviceType::Discrete, false),
                                           device("llvmpipe", DeviceType::Cpu)};
  EXPECT_EQ(choose_physical_device(devices, ""), 1u);
  EXPECT_THROW((void)choose_physical_device(devices, "0"), Error);
}

TEST(DeviceSelection, NoMatchNamesTheSelectorAndListsDevices) {
  try {
    (void)choose_physical_device(kMachine, "radeon");
    FAIL() << "expected relight::Error";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("'radeon'"), std::string::npos) << message;
    EXPECT_NE(message.find("2: NVIDIA GeForce RTX 3080 [discrete]"), std::string::npos) << message;
  }
  EXPECT_THROW((void)choose_physical_device({}, ""), Error);
}

TEST(BackendPolicy, WithoutDeviceEverythingRunsOnCpuUnlessVulkanIsForced) {
  EXPECT_EQ(choose_backend(StageKind::PerPixel, nullptr), Backend::Cpu);
  EXPECT_EQ(choose_backend(StageKind::Rasterisation, nullptr), Backend::Cpu);
  EXPECT_EQ(choose_backend(StageKind::PerPixel, nullptr, BackendPolicy::ForceCpu), Backend::Cpu);
  EXPECT_THROW((void)choose_backend(StageKind::PerPixel, nullptr, BackendPolicy::ForceVulkan), Error);
}

TEST(BackendPolicy, ParsesCommandLineSpellings) {
  EXPECT_EQ(parse_named(kBackendPolicyNames, "--backend", "auto"), BackendPolicy::Auto);
  EXPECT_EQ(parse_named(kBackendPolicyNames, "--backend", "cpu"), BackendPolicy::ForceCpu);
  EXPECT_EQ(parse_named(kBackendPolicyNames, "--backend", "vulkan"), BackendPolicy::ForceVulkan);
  EXPECT_THROW((void)parse_named(kBackendPolicyNames, "--backend", "gpu"), Error);
  EXPECT_STREQ(to_string(BackendPolicy::ForceVulkan), "vulkan");
}

}  // namespace
}  // namespace relight::vk
