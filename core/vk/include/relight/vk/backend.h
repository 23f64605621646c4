#pragma once
// Which backend a stage runs on. Measured on this project's machines (docs/platform.md):
// lavapipe, the CPU-type Vulkan device, runs a per-pixel compute dispatch slower than relight's
// plain CPU loop, so per-pixel stages default to the CPU path there and to Vulkan on a real GPU.
// Rasterisation-heavy work (the renderer) stays on Vulkan whenever a device exists.
// Deliberately free of Vulkan headers: the app's option parsing includes it.
#include <array>
#include <optional>
#include <string_view>

#include "relight/core/frame_graph.h"  // relight::Backend
#include "relight/core/named_values.h"

namespace relight::vk {

class VulkanContext;

/// Auto: the rule above. ForceCpu: the app's --cpu. ForceVulkan: use Vulkan even on lavapipe
/// (tests, benchmarks); choose_backend throws relight::Error if there is no device.
enum class BackendPolicy { Auto, ForceCpu, ForceVulkan };

enum class StageKind {
  PerPixel,       ///< independent work per pixel (filters, normals): CPU wins on lavapipe
  Rasterisation,  ///< triangle rendering: Vulkan whenever a device exists
};

/// `context` may be null (no Vulkan device): then Cpu, except ForceVulkan throws.
[[nodiscard]] Backend choose_backend(StageKind kind, const VulkanContext* context,
                                     BackendPolicy policy = BackendPolicy::Auto);

/// `--backend`'s values (case-sensitive).
inline constexpr std::array<NamedValue<BackendPolicy>, 3> kBackendPolicyNames{
    {{"auto", BackendPolicy::Auto}, {"cpu", BackendPolicy::ForceCpu}, {"vulkan", BackendPolicy::ForceVulkan}}};
[[nodiscard]] inline const char* to_string(BackendPolicy policy) { return name_of(kBackendPolicyNames, policy); }

}  // namespace relight::vk
