#pragma once
// The shadow-map atlas of shadow_maps.h, rasterised: one render pass over an R32F atlas, each
// light view drawn twice (the real layer's triangles into the upper half, the virtual layer's
// into the lower), then copied into a storage buffer for the shading pass.
// The CPU reference is shadow_atlas_cpu() (ray cast per texel centre).
#include <vulkan/vulkan.h>

#include <memory>
#include <optional>

#include "dir/mesh_raster_vk.h"
#include "relight/render/dir/shadow_maps.h"
#include "relight/vk/image.h"

namespace relight::render::detail {

class ShadowMapsVk {
 public:
  explicit ShadowMapsVk(vk::VulkanContext& context);

  /// `scene` must be valid (MrScene::validate()); its real layer casts through its
  /// coarse_real_meshes when it has them.
  void set_scene(const MrScene& scene);
  /// Records the draws of every view of `layout` and the copy of the atlas into atlas(); the
  /// atlas images are (re)made when the layout's size changes.
  void record(VkCommandBuffer cmd, const ShadowLayout& layout);
  /// Row-major floats of layout.atlas_width() x layout.atlas_height().
  [[nodiscard]] const vk::VulkanBuffer& atlas() const { return *atlas_buffer_; }

 private:
  struct Targets {
    vk::VulkanImage depth_image, colour_image;
    vk::UniqueFramebuffer framebuffer;
  };
  void ensure_targets(int width, int height);

  vk::VulkanContext& context_;
  vk::UniqueRenderPass render_pass_;
  MeshPipeline pipeline_;
  ScenePositions real_positions_, virtual_positions_;
  std::optional<Targets> targets_;
  std::unique_ptr<vk::VulkanBuffer> atlas_buffer_;
};

}  // namespace relight::render::detail
