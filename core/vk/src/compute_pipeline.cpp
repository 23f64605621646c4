#include "relight/vk/compute_pipeline.h"

#include "relight/core/error.h"
#include "relight/vk/buffer.h"
#include "relight/vk/check.h"
#include "relight/vk/context.h"

namespace relight::vk {

ComputePipeline::ComputePipeline(const VulkanContext& context, const ComputePipelineInfo& info)
    : device_(context.device()),
      storage_buffers_(info.storage_buffers),
      push_constant_bytes_(info.push_constant_bytes),
      sets_(context.device(), info.storage_buffers, VK_SHADER_STAGE_COMPUTE_BIT, info.max_descriptor_sets) {
  if (info.spirv.empty()) throw LogicError("ComputePipeline: no SPIR-V given");
  if (push_constant_bytes_ % 4 != 0 || push_constant_bytes_ > context.properties().limits.maxPushConstantsSize) {
    throw LogicError("ComputePipeline: push constants must be a multiple of 4 bytes within the device limit");
  }

  shader_ = create_shader_module(device_, info.spirv);
  const VkShaderModule shader = shader_.get();
  const VkDescriptorSetLayout set_layout = sets_.layout();

  const VkPushConstantRange push_range{VK_SHADER_STAGE_COMPUTE_BIT, 0, push_constant_bytes_};
  VkPipelineLayoutCreateInfo layout_info{};
  layout_info.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
  layout_info.setLayoutCount = 1;
  layout_info.pSetLayouts = &set_layout;
  layout_info.pushConstantRangeCount = push_constant_bytes_ > 0 ? 1 : 0;
  layout_info.pPushConstantRanges = &push_range;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  RELIGHT_VK_CHECK(vkCreatePipelineLayout(device_, &layout_info, nullptr, &layout));
  layout_ = UniquePipelineLayout(device_, layout);

  VkComputePipelineCreateInfo pipeline_info{};
  pipeline_info.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
  pipeline_info.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
  pipeline_info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  pipeline_info.stage.module = shader;
  pipeline_info.stage.pName = "main";
  pipeline_info.layout = layout;
  VkPipeline pipeline = VK_NULL_HANDLE;
  RELIGHT_VK_CHECK(vkCreateComputePipelines(device_, VK_NULL_HANDLE, 1, &pipeline_info, nullptr, &pipeline));
  pipeline_ = UniquePipeline(device_, pipeline);
}

UniqueDescriptorSet ComputePipeline::bind(std::initializer_list<const VulkanBuffer*> buffers) {
  return sets_.bind(buffers);
}

void ComputePipeline::dispatch(VkCommandBuffer cmd, const UniqueDescriptorSet& set,
                               std::span<const std::byte> push_constants, std::uint32_t groups_x,
                               std::uint32_t groups_y, std::uint32_t groups_z) const {
  if (push_constants.size() != push_constant_bytes_) {
    throw LogicError("ComputePipeline::dispatch: push constants do not match the pipeline's size");
  }
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_.get());
  const VkDescriptorSet raw = set.get();
  vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout_.get(), 0, 1, &raw, 0, nullptr);
  if (!push_constants.empty()) {
    vkCmdPushConstants(cmd, layout_.get(), VK_SHADER_STAGE_COMPUTE_BIT, 0,
                       static_cast<std::uint32_t>(push_constants.size()), push_constants.data());
  }
  if (groups_x > 0 && groups_y > 0 && groups_z > 0) vkCmdDispatch(cmd, groups_x, groups_y, groups_z);
}

}  // namespace relight::vk
