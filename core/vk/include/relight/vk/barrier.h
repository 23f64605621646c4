#pragma once
// Memory barriers between the steps of one command buffer (VulkanContext::submit only fences
// the whole submission): "what `from` wrote is visible to what `to` reads or writes next".
#include <vulkan/vulkan.h>

namespace relight::vk {

/// A global memory barrier from `from_stages` writes (shader, transfer or attachment writes) to
/// `to_stages` reads and writes.
void memory_barrier(VkCommandBuffer cmd, VkPipelineStageFlags from_stages, VkPipelineStageFlags to_stages);

/// The common case: compute (or transfer) results consumed by the next compute dispatch.
inline void compute_barrier(VkCommandBuffer cmd) {
  memory_barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                 VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT);
}

}  // namespace relight::vk
