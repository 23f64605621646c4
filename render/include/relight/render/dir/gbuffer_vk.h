#pragma once
// The rasterised G-buffer on Vulkan (Knecht's dissertation §5.2.2): one draw of every
// real and virtual triangle of an MrScene from the camera, into three RGBA32F targets
// (position + signed distance, normal + material, texture coordinates + footprint) and a depth
// buffer; the CPU reference is
// gbuffer_cpu() (gbuffer.h), and the two agree pixel for pixel up to triangle edges.
//
// Reads: the MrScene (set_scene, uploaded once), an MrCamera per render. Writes: GBuffer.
// Pixel centres sit at integer (u, v) as everywhere in relight (cx = 319.5 is the middle of a
// 640-pixel row), so the projection shifts by half a pixel into Vulkan's framebuffer convention.
#include <vulkan/vulkan.h>

#include <cstddef>
#include <memory>
#include <optional>
#include <span>

#include "relight/render/dir/gbuffer.h"

namespace relight::vk {
class VulkanContext;
class VulkanBuffer;
}

namespace relight::render {

class GBufferVk {
 public:
  /// Throws relight::Error when the device has no queue that does graphics and compute.
  GBufferVk(vk::VulkanContext& context, int width, int height);
  ~GBufferVk();
  GBufferVk(const GBufferVk&) = delete;
  GBufferVk& operator=(const GBufferVk&) = delete;

  /// Uploads the scene's triangles (meshes without vertex normals are drawn flat); with `only`,
  /// those of one layer (the rasterised RSMs of a real light see each layer on its own).
  void set_scene(const MrScene& scene, std::optional<Layer> only = std::nullopt);
  /// Renders the camera's view and reads the G-buffer back. The camera's intrinsics must have
  /// this renderer's size.
  [[nodiscard]] GBuffer render(const MrCamera& camera);
  /// Records the draw and a copy of the targets into `destination` (packed_bytes(): first every
  /// pixel's position.xyz + signed distance, then every pixel's normal.xyz + material index, then
  /// every pixel's texture coordinates + footprint), for
  /// a renderer that goes on shading on the GPU.
  void record(VkCommandBuffer cmd, const MrCamera& camera, const vk::VulkanBuffer& destination);
  [[nodiscard]] static std::size_t packed_bytes(int width, int height);
  /// The GBuffer of a packed copy (distance 0 = nothing drawn); a copy of the first two blocks
  /// only (8 floats per pixel) gives a GBuffer without texcoord.
  [[nodiscard]] static GBuffer unpack(std::span<const float> packed, int width, int height);
  /// unpack() into `out`, whose images are reused where they have the size already (a renderer's
  /// per-frame read-back: fresh 640x480 images cost more in page faults than the unpacking).
  static void unpack_into(std::span<const float> packed, int width, int height, GBuffer& out);
  /// GPU time of the last render's draw, milliseconds (0 without timestamp support).
  [[nodiscard]] double last_gpu_ms() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace relight::render
