#include "relight/vk/storage_buffer_sets.h"

#include <algorithm>
#include <vector>

#include "relight/core/error.h"
#include "relight/vk/buffer.h"
#include "relight/vk/check.h"

namespace relight::vk {

UniqueShaderModule create_shader_module(VkDevice device, std::span<const std::uint32_t> spirv) {
  if (spirv.empty()) throw LogicError("create_shader_module: no SPIR-V given");
  VkShaderModuleCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
  info.codeSize = spirv.size_bytes();
  info.pCode = spirv.data();
  VkShaderModule module = VK_NULL_HANDLE;
  RELIGHT_VK_CHECK(vkCreateShaderModule(device, &info, nullptr, &module));
  return UniqueShaderModule(device, module);
}

StorageBufferSets::StorageBufferSets(VkDevice device, std::uint32_t buffers, VkShaderStageFlags stages,
                                     std::uint32_t max_sets)
    : device_(device), buffers_(buffers) {
  std::vector<VkDescriptorSetLayoutBinding> bindings(buffers);
  for (std::uint32_t i = 0; i < buffers; ++i) bindings[i] = {i, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, stages, nullptr};
  VkDescriptorSetLayoutCreateInfo set_info{};
  set_info.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
  set_info.bindingCount = buffers;
  set_info.pBindings = bindings.data();
  VkDescriptorSetLayout layout = VK_NULL_HANDLE;
  RELIGHT_VK_CHECK(vkCreateDescriptorSetLayout(device, &set_info, nullptr, &layout));
  layout_ = UniqueDescriptorSetLayout(device, layout);

  const VkDescriptorPoolSize pool_size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, std::max(1u, buffers) * max_sets};
  VkDescriptorPoolCreateInfo pool_info{};
  pool_info.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
  pool_info.flags = VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT;  // sets are freed one by one (RAII)
  pool_info.maxSets = max_sets;
  pool_info.poolSizeCount = 1;
  pool_info.pPoolSizes = &pool_size;
  VkDescriptorPool pool = VK_NULL_HANDLE;
  RELIGHT_VK_CHECK(vkCreateDescriptorPool(device, &pool_info, nullptr, &pool));
  pool_ = UniqueDescriptorPool(device, pool);
}

UniqueDescriptorSet StorageBufferSets::bind(std::initializer_list<const VulkanBuffer*> buffers) {
  if (buffers.size() != buffers_) throw LogicError("StorageBufferSets::bind: wrong number of buffers");
  const VkDescriptorSetLayout set_layout = layout_.get();
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

}  // namespace relight::vk
