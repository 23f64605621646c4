#pragma once
// The imperfect shadow maps of ism.h on Vulkan: a splat dispatch over (point slot, VPL, layer)
// with atomicMin into the atlas, then pull-push dispatches level by level. The CPU reference is
// ism_atlas_cpu().
#include <vulkan/vulkan.h>

#include <memory>
#include <optional>

#include "relight/render/dir/ism.h"
#include "relight/vk/buffer.h"
#include "relight/vk/compute_pipeline.h"

namespace relight::render::detail {

class IsmVk {
 public:
  explicit IsmVk(vk::VulkanContext& context);

  /// Uploads both point pools (real first).
  void set_points(const IsmPointPools& points);
  /// Records the atlas of `vpl_count` VPLs from `vpls` (GpuVpl records, see dir_vk.cpp), the
  /// last `emitter_count` of them emitters (ism.h: fewer pull-push levels).
  void record(VkCommandBuffer cmd, const vk::VulkanBuffer& vpls, std::uint32_t vpl_count, std::uint32_t emitter_count,
              const IsmOptions& options);
  [[nodiscard]] const vk::VulkanBuffer& atlas() const { return *atlas_; }

 private:
  void ensure_buffers(std::size_t atlas_floats, std::size_t pyramid_floats);

  vk::VulkanContext& context_;
  vk::ComputePipeline splat_, pull_push_;
  std::optional<vk::VulkanBuffer> points_;
  std::unique_ptr<vk::VulkanBuffer> atlas_, pyramid_;
  std::uint32_t real_points_ = 0, virtual_points_ = 0;
  Eigen::Vector4f virtual_bounds_ = Eigen::Vector4f::Zero();
  Eigen::Vector4f scene_bounds_ = Eigen::Vector4f::Zero();
  vk::UniqueDescriptorSet splat_set_, pull_push_set_;
};

}  // namespace relight::render::detail
