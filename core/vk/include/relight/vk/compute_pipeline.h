#pragma once
// ComputePipeline: a compute shader with the common relight binding layout, i.e. set 0 holds
// `storage_buffers` storage buffers at bindings 0..n-1 (in the order given to bind()) and an
// optional push-constant block. It owns the shader module, descriptor-set layout, pipeline layout,
// pipeline and a descriptor pool for its sets.
//
//   ComputePipeline pipeline(context, {.spirv = shaders::depth_box_filter_comp,
//                                      .storage_buffers = 2, .push_constant_bytes = sizeof(Params)});
//   const auto set = pipeline.bind({&input, &output});  // must not outlive `pipeline`
//   context.submit([&](VkCommandBuffer cmd) { pipeline.dispatch(cmd, set, params, groups_x, groups_y); });
#include <vulkan/vulkan.h>

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <span>

#include "relight/vk/handles.h"
#include "relight/vk/storage_buffer_sets.h"

namespace relight::vk {

class VulkanBuffer;
class VulkanContext;

struct ComputePipelineInfo {
  std::span<const std::uint32_t> spirv{};   ///< embedded SPIR-V words (see cmake/EmbedShaders.cmake)
  std::uint32_t storage_buffers = 1;        ///< set 0, bindings 0..storage_buffers-1
  std::uint32_t push_constant_bytes = 0;    ///< multiple of 4, <= 128 (the guaranteed minimum)
  std::uint32_t max_descriptor_sets = 16;   ///< how many bind() results may exist at once
};

class ComputePipeline {
 public:
  ComputePipeline(const VulkanContext& context, const ComputePipelineInfo& info);

  /// A descriptor set pointing binding i at buffers[i] (whole buffer). The set must be destroyed
  /// before this pipeline, and must not be destroyed while a submission using it runs.
  [[nodiscard]] UniqueDescriptorSet bind(std::initializer_list<const VulkanBuffer*> buffers);

  /// Records bind + push constants + vkCmdDispatch(groups_x, groups_y, groups_z).
  void dispatch(VkCommandBuffer cmd, const UniqueDescriptorSet& set, std::span<const std::byte> push_constants,
                std::uint32_t groups_x, std::uint32_t groups_y, std::uint32_t groups_z = 1) const;
  template <class Params>
  void dispatch(VkCommandBuffer cmd, const UniqueDescriptorSet& set, const Params& params, std::uint32_t groups_x,
                std::uint32_t groups_y, std::uint32_t groups_z = 1) const {
    dispatch(cmd, set, std::as_bytes(std::span<const Params>(&params, 1)), groups_x, groups_y, groups_z);
  }

  /// Work groups needed to cover `extent` items with groups of `local_size`.
  [[nodiscard]] static std::uint32_t group_count(std::uint32_t extent, std::uint32_t local_size) {
    return (extent + local_size - 1) / local_size;
  }

 private:
  VkDevice device_ = VK_NULL_HANDLE;
  std::uint32_t storage_buffers_ = 0;
  std::uint32_t push_constant_bytes_ = 0;
  StorageBufferSets sets_;
  UniqueShaderModule shader_;
  UniquePipelineLayout layout_;
  UniquePipeline pipeline_;
};

}  // namespace relight::vk
