#include "dir/shadow_maps_vk.h"

#include <array>
#include <cstring>

#include "relight/shaders/shadow_vert.h"
#include "relight/shaders/shadow_frag.h"
#include "relight/vk/context.h"

namespace relight::render::detail {
namespace {

constexpr VkFormat kColourFormat = VK_FORMAT_R32_SFLOAT;
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;

struct ViewConstants {
  float world_to_clip[16];  // column-major
  float eye[4];
};

}  // namespace

ShadowMapsVk::ShadowMapsVk(vk::VulkanContext& context)
    : context_(context),
      render_pass_(create_raster_pass(context.device(), std::array{kColourFormat}, kDepthFormat)),
      pipeline_(create_mesh_pipeline(context.device(), {.render_pass = render_pass_.get(),
                                                        .vertex_spirv = shaders::shadow_vert,
                                                        .fragment_spirv = shaders::shadow_frag,
                                                        .colour_targets = 1,
                                                        .push_constant_bytes = sizeof(ViewConstants),
                                                        .position_only = true})) {}

void ShadowMapsVk::set_scene(const MrScene& scene) {
  // The real layer's occluders: the scene's stand-ins when it has them (mr_scene.h).
  upload_scene_positions(context_, scene.coarse_real_meshes.empty() ? scene.meshes : scene.coarse_real_meshes,
                         MeshLayers::Real, real_positions_);
  upload_scene_positions(context_, scene.meshes, MeshLayers::Virtual, virtual_positions_);
}

void ShadowMapsVk::ensure_targets(int width, int height) {
  const auto w = static_cast<std::uint32_t>(width), h = static_cast<std::uint32_t>(height);
  if (targets_ && targets_->colour_image.width() == w && targets_->colour_image.height() == h) return;
  targets_.reset();
  vk::VulkanImage depth(context_, w, h, kDepthFormat, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT,
                        VK_IMAGE_ASPECT_DEPTH_BIT);
  vk::VulkanImage colour(context_, w, h, kColourFormat,
                         VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
  auto framebuffer = create_framebuffer(context_.device(), render_pass_.get(), std::array{colour.view(), depth.view()}, w, h);
  targets_.emplace(Targets{std::move(depth), std::move(colour), std::move(framebuffer)});
  atlas_buffer_ = std::make_unique<vk::VulkanBuffer>(context_, sizeof(float) * w * h);
}

void ShadowMapsVk::record(VkCommandBuffer cmd, const ShadowLayout& layout) {
  ensure_targets(layout.atlas_width(), layout.atlas_height());
  const auto width = static_cast<std::uint32_t>(layout.atlas_width());
  const auto height = static_cast<std::uint32_t>(layout.atlas_height());
  std::array<VkClearValue, 2> clear{};
  clear[0].color.float32[0] = kShadowEmpty;
  clear[1].depthStencil = {1.f, 0};
  VkRenderPassBeginInfo begin{};
  begin.sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO;
  begin.renderPass = render_pass_.get();
  begin.framebuffer = targets_->framebuffer.get();
  begin.renderArea = {{0, 0}, {width, height}};
  begin.clearValueCount = static_cast<std::uint32_t>(clear.size());
  begin.pClearValues = clear.data();
  vkCmdBeginRenderPass(cmd, &begin, VK_SUBPASS_CONTENTS_INLINE);
  const auto tile = static_cast<std::uint32_t>(layout.tile);
  for (std::size_t v = 0; v < layout.views.size(); ++v) {
    for (int layer = 0; layer < 2; ++layer) {
      ViewConstants constants{};
      std::memcpy(constants.world_to_clip, layout.view(v, layer).world_to_clip.data(), sizeof constants.world_to_clip);
      std::memcpy(constants.eye, layout.view(v, layer).eye.data(), sizeof constants.eye);
      const auto [x, y] = layout.tile_origin(static_cast<int>(v), layer);
      const VkRect2D area{{x, y}, {tile, tile}};
      draw_scene(cmd, pipeline_, layer == 0 ? real_positions_ : virtual_positions_,
                 std::as_bytes(std::span(&constants, 1)), area);
    }
  }
  vkCmdEndRenderPass(cmd);
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {width, height, 1};
  vkCmdCopyImageToBuffer(cmd, targets_->colour_image.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                         atlas_buffer_->handle(), 1, &region);
}

}  // namespace relight::render::detail
