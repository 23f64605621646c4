#include "relight/vk/barrier.h"

namespace relight::vk {
namespace {

/// The write accesses (source) or all accesses (destination) that `stages` can perform.
VkAccessFlags accesses(VkPipelineStageFlags stages, bool writes_only) {
  VkAccessFlags out = 0;
  if (stages & (VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT))
    out |= VK_ACCESS_SHADER_WRITE_BIT | (writes_only ? 0 : VK_ACCESS_SHADER_READ_BIT);
  if (stages & VK_PIPELINE_STAGE_TRANSFER_BIT)
    out |= VK_ACCESS_TRANSFER_WRITE_BIT | (writes_only ? 0 : VK_ACCESS_TRANSFER_READ_BIT);
  if (stages & VK_PIPELINE_STAGE_HOST_BIT) out |= VK_ACCESS_HOST_WRITE_BIT | (writes_only ? 0 : VK_ACCESS_HOST_READ_BIT);
  if (stages & VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT)
    out |= VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | (writes_only ? 0 : VK_ACCESS_COLOR_ATTACHMENT_READ_BIT);
  return out;
}

}  // namespace

void memory_barrier(VkCommandBuffer cmd, VkPipelineStageFlags from_stages, VkPipelineStageFlags to_stages) {
  VkMemoryBarrier barrier{};
  barrier.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
  barrier.srcAccessMask = accesses(from_stages, true);
  barrier.dstAccessMask = accesses(to_stages, false);
  vkCmdPipelineBarrier(cmd, from_stages, to_stages, 0, 1, &barrier, 0, nullptr, 0, nullptr);
}

}  // namespace relight::vk
