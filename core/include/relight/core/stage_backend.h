#pragma once
// How a stage's backend is chosen - one idiom for every stage that has a GPU version:
//
//   std::unique_ptr<Stage> make_<stage>_stage(Backend backend, vk::VulkanContext* context, ...);
//
// declared in the stage's Vulkan-free header, defined beside its Vulkan code. The caller picks
// `backend` (app/ with vk::choose_backend); Backend::Vulkan needs a non-null `context`. A family
// of stages added together takes the same pair (add_brdf_stages, add_dir_stages). Whatever the
// factory builds, Stage::backend() then says where the stage's work runs, and the graph's
// timings say whether its buffers lived on the device (StageTimings::device_buffers).
#include <memory>
#include <string>
#include <string_view>
#include <utility>

#include "relight/core/error.h"
#include "relight/core/frame_graph.h"

namespace relight {

namespace vk {
class VulkanContext;
}  // namespace vk

/// `context` for a Vulkan stage; throws LogicError naming `factory` when it is null.
[[nodiscard]] inline vk::VulkanContext& require_vulkan_context(vk::VulkanContext* context, std::string_view factory) {
  if (!context) throw LogicError(std::string(factory) + ": the Vulkan backend needs a VulkanContext");
  return *context;
}

/// For a stage class that runs either way (null context = CPU): the context for `backend`, null
/// for Backend::Cpu; throws LogicError naming `factory` when Vulkan has none.
[[nodiscard]] inline vk::VulkanContext* context_for_backend(Backend backend, vk::VulkanContext* context,
                                                            std::string_view factory) {
  return backend == Backend::Cpu ? nullptr : &require_vulkan_context(context, factory);
}

/// The factory body for a CPU/Vulkan pair of stage classes whose constructors take the same
/// arguments, the Vulkan one after the context: CpuStage(args...) or VulkanStage(*context, args...).
template <class CpuStage, class VulkanStage, class... Args>
[[nodiscard]] std::unique_ptr<Stage> make_stage_for_backend(Backend backend, vk::VulkanContext* context,
                                                            std::string_view factory, Args&&... args) {
  if (backend == Backend::Cpu) return std::make_unique<CpuStage>(std::forward<Args>(args)...);
  return std::make_unique<VulkanStage>(require_vulkan_context(context, factory), std::forward<Args>(args)...);
}

}  // namespace relight
