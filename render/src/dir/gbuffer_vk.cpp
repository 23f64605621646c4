#include "relight/render/dir/gbuffer_vk.h"

#include <array>
#include <cstring>
#include <vector>

#include "relight/core/error.h"
#include "relight/shaders/gbuffer_frag.h"
#include "relight/shaders/gbuffer_vert.h"
#include "relight/vk/buffer.h"
#include "relight/vk/context.h"
#include "relight/vk/image.h"
#include "relight/vk/timer.h"
#include "dir/mesh_raster_vk.h"

namespace relight::render {
namespace {

constexpr VkFormat kTargetFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;
constexpr float kNear = 0.02f;
constexpr float kFar = 200.f;

struct CameraConstants {
  float world_to_clip[16];  // column-major
  float centre[4];
};

/// Vulkan clip space from relight's pinhole camera (x right, y down, z forward; pixel centres at
/// integer coordinates, Vulkan's at +0.5).
Eigen::Matrix4f world_to_clip(const MrCamera& camera) {
  const PinholeIntrinsics& k = camera.intrinsics;
  const auto w = static_cast<float>(k.width), h = static_cast<float>(k.height);
  Eigen::Matrix4f projection = Eigen::Matrix4f::Zero();
  projection(0, 0) = static_cast<float>(2.0 * k.fx) / w;
  projection(0, 2) = static_cast<float>(2.0 * (k.cx + 0.5)) / w - 1.f;
  projection(1, 1) = static_cast<float>(2.0 * k.fy) / h;
  projection(1, 2) = static_cast<float>(2.0 * (k.cy + 0.5)) / h - 1.f;
  projection(2, 2) = kFar / (kFar - kNear);
  projection(2, 3) = -kFar * kNear / (kFar - kNear);
  projection(3, 2) = 1.f;
  return projection * camera.camera_to_world.inverse().matrix().cast<float>();
}

}  // namespace

struct GBufferVk::Impl {
  Impl(vk::VulkanContext& context, int width, int height);

  vk::VulkanContext& context;
  std::uint32_t width, height;
  vk::UniqueRenderPass render_pass;
  vk::VulkanImage position_target, normal_target, texcoord_target, depth_target;
  vk::UniqueFramebuffer framebuffer;
  detail::MeshPipeline pipeline;
  vk::VulkanBuffer readback;
  vk::GpuTimer timer;
  detail::SceneVertices vertices;
  double gpu_ms = 0.0;
};

GBufferVk::Impl::Impl(vk::VulkanContext& context, int width, int height)
    : context(context),
      width(static_cast<std::uint32_t>(width)),
      height(static_cast<std::uint32_t>(height)),
      render_pass(detail::create_raster_pass(context.device(), std::array{kTargetFormat, kTargetFormat, kTargetFormat},
                                             kDepthFormat)),
      position_target(context, this->width, this->height, kTargetFormat,
                      VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT),
      normal_target(context, this->width, this->height, kTargetFormat,
                    VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT),
      texcoord_target(context, this->width, this->height, kTargetFormat,
                      VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT),
      depth_target(context, this->width, this->height, kDepthFormat, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT,
                   VK_IMAGE_ASPECT_DEPTH_BIT),
      framebuffer(detail::create_framebuffer(
          context.device(), render_pass.get(),
          std::array{position_target.view(), normal_target.view(), texcoord_target.view(), depth_target.view()},
          this->width, this->height)),
      pipeline(detail::create_mesh_pipeline(context.device(), {.render_pass = render_pass.get(),
                                                               .vertex_spirv = shaders::gbuffer_vert,
                                                               .fragment_spirv = shaders::gbuffer_frag,
                                                               .colour_targets = 3,
                                                               .push_constant_bytes = sizeof(CameraConstants)})),
      readback(context, GBufferVk::packed_bytes(width, height), vk::BufferDomain::Readback),
      timer(context) {}

GBufferVk::GBufferVk(vk::VulkanContext& context, int width, int height) {
  if (width <= 0 || height <= 0) throw Error("the G-buffer size must be positive");
  if (context.graphics_queue_family() != context.compute_queue_family())
    throw Error("Vulkan device '" + context.device_info().name + "' has no queue for both graphics and compute");
  impl_ = std::make_unique<Impl>(context, width, height);
}

GBufferVk::~GBufferVk() = default;

double GBufferVk::last_gpu_ms() const { return impl_->gpu_ms; }

void GBufferVk::set_scene(const MrScene& scene, std::optional<Layer> only) {
  const detail::MeshLayers layers = !only                 ? detail::MeshLayers::All
                                    : *only == Layer::Real ? detail::MeshLayers::Real
                                                           : detail::MeshLayers::Virtual;
  detail::upload_scene_vertices(impl_->context, scene, layers, impl_->vertices);
}

std::size_t GBufferVk::packed_bytes(int width, int height) {
  return 12 * sizeof(float) * static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
}

void GBufferVk::record(VkCommandBuffer cmd, const MrCamera& camera, const vk::VulkanBuffer& destination) {
  Impl& g = *impl_;
  if (!g.vertices.buffer) throw LogicError("GBufferVk::set_scene must come before render");
  if (camera.intrinsics.width != static_cast<int>(g.width) || camera.intrinsics.height != static_cast<int>(g.height))
    throw Error("GBufferVk: the camera's image size differs from the renderer's");
  if (destination.size_bytes() < packed_bytes(camera.intrinsics.width, camera.intrinsics.height))
    throw LogicError("GBufferVk::record: the destination buffer is too small");
  CameraConstants constants{};
  const Eigen::Matrix4f clip = world_to_clip(camera);
  std::memcpy(constants.world_to_clip, clip.data(), sizeof constants.world_to_clip);
  const Eigen::Vector3f centre = camera.camera_to_world.translation().cast<float>();
  constants.centre[0] = centre.x();
  constants.centre[1] = centre.y();
  constants.centre[2] = centre.z();

  std::array<VkClearValue, 4> clear{};
  clear[3].depthStencil = {1.f, 0};
  VkRenderPassBeginInfo begin{};
  begin.sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO;
  begin.renderPass = g.render_pass.get();
  begin.framebuffer = g.framebuffer.get();
  begin.renderArea = {{0, 0}, {g.width, g.height}};
  begin.clearValueCount = static_cast<std::uint32_t>(clear.size());
  begin.pClearValues = clear.data();
  g.timer.start(cmd);
  vkCmdBeginRenderPass(cmd, &begin, VK_SUBPASS_CONTENTS_INLINE);
  detail::draw_scene(cmd, g.pipeline, g.vertices, std::as_bytes(std::span(&constants, 1)), begin.renderArea);
  vkCmdEndRenderPass(cmd);
  g.timer.stop(cmd);
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {g.width, g.height, 1};
  vkCmdCopyImageToBuffer(cmd, g.position_target.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, destination.handle(), 1, &region);
  region.bufferOffset = static_cast<VkDeviceSize>(g.width) * g.height * 4 * sizeof(float);
  vkCmdCopyImageToBuffer(cmd, g.normal_target.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, destination.handle(), 1, &region);
  region.bufferOffset *= 2;
  vkCmdCopyImageToBuffer(cmd, g.texcoord_target.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, destination.handle(), 1,
                         &region);
}

GBuffer GBufferVk::render(const MrCamera& camera) {
  Impl& g = *impl_;
  g.context.submit([&](VkCommandBuffer cmd) { record(cmd, camera, g.readback); });
  g.gpu_ms = g.timer.elapsed_ms().value_or(0.0);
  const std::size_t floats = packed_bytes(static_cast<int>(g.width), static_cast<int>(g.height)) / sizeof(float);
  const std::span<const std::byte> mapped = g.readback.mapped_bytes();
  return unpack({reinterpret_cast<const float*>(mapped.data()), floats}, static_cast<int>(g.width),
                static_cast<int>(g.height));
}

GBuffer GBufferVk::unpack(std::span<const float> data, int width, int height) {
  GBuffer out;
  unpack_into(data, width, height, out);
  return out;
}

void GBufferVk::unpack_into(std::span<const float> data, int width, int height, GBuffer& out) {
  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  if (data.size() < 8 * pixels) throw LogicError("GBufferVk::unpack: too few values");
  const bool texcoords = data.size() >= 12 * pixels;
  const auto sized = [width, height]<typename T>(Image<T>& image) {
    if (image.width() != width || image.height() != height) image = Image<T>(width, height);
  };
  sized(out.position);
  sized(out.normal);
  sized(out.material);
  sized(out.virtual_surface);
  sized(out.distance);
  if (texcoords) {
    sized(out.texcoord);
    sized(out.tangent);
  } else {
    out.texcoord = {};
    out.tangent = {};
  }
  for (std::size_t i = 0; i < pixels; ++i) {
    const float* p = &data[4 * i];
    const float* n = &data[4 * (pixels + i)];
    const bool drawn = p[3] != 0.f;  // cleared: nothing drawn
    out.position.pixels()[i] = drawn ? Float3{p[0], p[1], p[2]} : Float3{};
    out.distance.pixels()[i] = std::abs(p[3]);
    out.virtual_surface.pixels()[i] = p[3] < 0.f ? 1 : 0;
    out.normal.pixels()[i] = drawn ? Float3{n[0], n[1], n[2]} : Float3{};
    out.material.pixels()[i] = drawn ? static_cast<std::uint16_t>(n[3] + 1.f) : std::uint16_t{0};
    if (texcoords) {
      const float* t = &data[4 * (2 * pixels + i)];
      out.texcoord.pixels()[i] = drawn ? Float3{t[0], t[1], t[2]} : Float3{};
      out.tangent.pixels()[i] = drawn ? t[3] : 0.f;
    }
  }
}

}  // namespace relight::render
