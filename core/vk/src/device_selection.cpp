#include "relight/vk/device_selection.h"

#include <algorithm>
#include <cctype>
#include <charconv>

#include "relight/core/error.h"

namespace relight::vk {

const char* to_string(DeviceType type) {
  switch (type) {
    case DeviceType::Discrete: return "discrete";
    case DeviceType::Integrated: return "integrated";
    case DeviceType::Virtual: return "virtual";
    case DeviceType::Cpu: return "cpu";
    case DeviceType::Other: return "other";
  }
  return "other";
}

namespace {

int preference(DeviceType type) {
  switch (type) {
    case DeviceType::Discrete: return 4;
    case DeviceType::Integrated: return 3;
    case DeviceType::Virtual: return 2;
    case DeviceType::Cpu: return 1;
    case DeviceType::Other: return 0;
  }
  return 0;
}

std::string lower(std::string_view text) {
  std::string out(text);
  std::transform(out.begin(), out.end(), out.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

bool matches(const DeviceInfo& device, std::size_t index, std::string_view selector) {
  std::size_t wanted_index = 0;
  const auto [end, error] = std::from_chars(selector.data(), selector.data() + selector.size(), wanted_index);
  if (error == std::errc{} && end == selector.data() + selector.size()) return wanted_index == index;
  const std::string wanted = lower(selector);
  if (wanted == to_string(device.type)) return true;
  return lower(device.name).find(wanted) != std::string::npos;
}

}  // namespace

std::string describe_devices(const std::vector<DeviceInfo>& devices) {
  std::string text;
  for (std::size_t i = 0; i < devices.size(); ++i) {
    text += "  " + std::to_string(i) + ": " + devices[i].name + " [" + to_string(devices[i].type) + "]";
    if (!devices[i].usable) text += " (unusable: " + devices[i].unusable_reason + ")";
    text += '\n';
  }
  return text;
}

std::size_t choose_physical_device(const std::vector<DeviceInfo>& devices, std::string_view selector) {
  if (devices.empty()) throw Error("no Vulkan physical device found (is a Vulkan driver such as mesa-vulkan-drivers installed?)");
  std::size_t best = devices.size();
  for (std::size_t i = 0; i < devices.size(); ++i) {
    if (!devices[i].usable) continue;
    if (!selector.empty() && !matches(devices[i], i, selector)) continue;
    if (best == devices.size() || preference(devices[i].type) > preference(devices[best].type)) best = i;
  }
  if (best != devices.size()) return best;
  const std::string what = selector.empty() ? std::string("no usable Vulkan device")
                                            : "no usable Vulkan device matches '" + std::string(selector) + "'";
  throw Error(what + "; devices:\n" + describe_devices(devices));
}

}  // namespace relight::vk
