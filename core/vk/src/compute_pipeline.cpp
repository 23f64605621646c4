#include "relight/vk/compute_pipeline.h"

#include <algorithm>
#include <vector>

#include "relight/core/error.h"
#include "relight/vk/buffer.h"
#include "relight/vk/check.h"
#include "relight/vk/context.h"

namespace relight::vk {

ComputePipeline::ComputePipeline(const VulkanContext& context, const ComputePipelineInfo& info)
    : device_(context.device()), storage_buffers_(info.storage_buffers), push_constant_bytes_(info.push_constant_bytes) {
  if (info.spirv.empty()) throw LogicError("ComputePipeline: no SPIR-V given");
  if (push_constant_bytes_ % 4 != 0 || push_constant_bytes_ > context.properties().limits.maxPushConstantsSize) {
    throw LogicError("ComputePipeline: push constants must be a multiple of 4 bytes within the device limit");
  }

  VkShaderModuleCreateInfo shader_info{};
  shader_info.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
  shader_info.codeSize = info.spirv.size_bytes();
  shader_info.pCode = info.spirv.data();
  VkShaderModule shader = VK_NULL_HANDLE;
  RELIGHT_VK_CHECK(vkCreateShaderModule(device_, &shader_info, nullptr, &shader));
  shader_ = UniqueShaderModule(device_, shader);

  std::vector<VkDescriptorSetLayoutBinding> bindings(storage_buffers_);
  for (std::uint32_t i = 0; i < storage_buffers_; ++i) {
    bindings[i] = {i, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
  }
  VkDescriptorSetLayoutCreateInfo set_info{};
  set_info.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
  set_info.bindingCount = storage_buffers_;
  set_info.pBindings = bindings.data();
  VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
  RELIGHT_VK_CHECK(vkCreateDescriptorSetLayout(device_, &set_info, nullptr, &set_layout));
  set_layout_ = UniqueDescriptorSetLayout(device_, set_layout);

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

  const VkDescriptorPoolSize pool_size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                                       std::max(1u, storage_buffers_) * info.max_descriptor_sets};
  VkDescriptorPoolCreateInfo pool_info{};
  pool_info.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
  pool_info.flags = VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT;  // sets are freed one by one (RAII)
  pool_info.maxSets = info.max_descriptor_sets;
  pool_info.poolSizeCount = 1;
  pool_info.pPoolSizes = &pool_size;
  VkDescriptorPool pool = VK_NULL_HANDLE;
  RELIGHT_VK_CHECK(vkCreateDescriptorPool(device_, &pool_info, nullptr, &pool));
  pool_ = UniqueDescriptorPool(device_, pool);
}

UniqueDescriptorSet ComputePipeline::bind(std::initializer_list<const VulkanBuffer*> buffers) {
  if (buffers.size() != storage_buffers_) throw LogicError("ComputePipeline::bind: wrong number of buffers");
  const VkDescriptorSetLayout set_layout = set_layout_.get();
  VkDescriptorSetAllocateInfo allocate{};
  allocate.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
  allocate.descriptorPool = pool_.get();
  allocate.descriptorSetCount = 1;
  allocate.pSetLayouts = &set_layout;
  VkDescriptorSet raw = VK_NULL_HANDLE;
  RELIGHT_VK_CHECK(vkAllocateDescriptorSets(device_, &allocate, &raw));
  UniqueDescriptorSet set(device_, pool_.get(), raw);

  std::vector<VkDescriptorBufferInfo> infos;
  infos.reserve(buffers.size());
  for (const VulkanBuffer* buffer : buffers) infos.push_back({buffer->handle(), 0, VK_WHOLE_SIZE});
  std::vector<VkWriteDescriptorSet> writes(infos.size());
  for (std::uint32_t i = 0; i < writes.size(); ++i) {
    writes[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    writes[i].dstSet = raw;
    writes[i].dstBinding = i;
    writes[i].descriptorCount = 1;
    writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    writes[i].pBufferInfo = &infos[i];
  }
  vkUpdateDescriptorSets(device_, static_cast<std::uint32_t>(writes.size()), writes.data(), 0, nullptr);
  return set;
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
