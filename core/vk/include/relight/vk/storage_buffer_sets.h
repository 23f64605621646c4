#pragma once
// The parts every relight pipeline shares: a shader module from embedded SPIR-V, and the common
// binding layout (set 0 = n storage buffers at bindings 0..n-1) with a pool for its sets.
#include <vulkan/vulkan.h>

#include <cstdint>
#include <initializer_list>
#include <span>

#include "relight/vk/handles.h"

namespace relight::vk {

class VulkanBuffer;

[[nodiscard]] UniqueShaderModule create_shader_module(VkDevice device, std::span<const std::uint32_t> spirv);

class StorageBufferSets {
 public:
  StorageBufferSets(VkDevice device, std::uint32_t buffers, VkShaderStageFlags stages, std::uint32_t max_sets);

  [[nodiscard]] VkDescriptorSetLayout layout() const { return layout_.get(); }
  [[nodiscard]] std::uint32_t buffers() const { return buffers_; }
  /// A set pointing binding i at buffers[i] (whole buffer); it must not outlive this object.
  [[nodiscard]] UniqueDescriptorSet bind(std::initializer_list<const VulkanBuffer*> buffers);

 private:
  VkDevice device_ = VK_NULL_HANDLE;
  std::uint32_t buffers_ = 0;
  UniqueDescriptorSetLayout layout_;
  UniqueDescriptorPool pool_;
};

}  // namespace relight::vk
