#pragma once
// What the renderer's rasterising passes share (the G-buffer, gbuffer_vk.h, and the light-view
// shadow maps, shadow_maps_vk.h): the scene's triangles as one vertex buffer, a render pass
// over colour targets + a depth buffer, and a triangle pipeline with dynamic viewport, so that
// one pipeline can draw into any tile of an atlas.
#include <vulkan/vulkan.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <span>

#include "relight/render/scene/mr_scene.h"
#include "relight/vk/buffer.h"
#include "relight/vk/handles.h"

namespace relight::vk {
class VulkanContext;
}

namespace relight::render::detail {

/// One vertex of the G-buffer pass. The flat `info` attribute stands in for gl_PrimitiveID (which
/// would need the geometry-shader feature): a triangle takes the info of its first corner, Vulkan's
/// provoking vertex. The draw is indexed: a vertex is shared where the triangles it is the first
/// corner of agree on their info, and a triangle that disagrees gets its own copy of its first
/// corner (upload_scene_vertices), so the G-buffer is the same bit for bit as with a vertex per
/// corner. A reconstruction shares each vertex among about six triangles: the replay's 640x480
/// upload went from 72 to 19 MB and from 2.5 ms (38 ms when the buffer grew) to 1.9 ms. The draw
/// itself took as long on lavapipe (25-34 ms): there the 600k sub-pixel triangles' setup costs,
/// not their vertices. The shadow pass, which needs positions only, draws ScenePositions: its
/// shadow maps of the replay's 8 probe lights on lavapipe took 76-213 ms per frame with corners,
/// 65-83 ms indexed.
inline constexpr std::uint32_t kVirtualBit = 0x80000000u;
inline constexpr std::uint32_t kTexcoordBit = 0x40000000u;  ///< the mesh has texture coordinates

struct RasterVertex {
  float position[3];
  float normal[3];
  std::uint32_t info;  ///< bits 0-29: material index; bit 30: has texcoord; bit 31: virtual
  float texcoord[2];   ///< (0, 0) without texture coordinates
};

struct SceneVertices {
  std::optional<vk::VulkanBuffer> buffer, indices;
  std::uint32_t index_count = 0;
};

enum class MeshLayers { All, Real, Virtual };

/// The triangles of `scene` in `layers` into `vertices`, indexed (above); meshes without vertex
/// normals get their face normal, on three corners of their own per triangle. The buffer is kept when it is large
/// enough and grows with headroom, so that the reconstruction mesh, whose size changes every frame, needs no allocation
/// in a steady run. The previous frame's draws must have completed (submissions wait).
void upload_scene_vertices(vk::VulkanContext& context, const MrScene& scene, MeshLayers layers,
                           SceneVertices& vertices);

/// The triangles of `scene` in `layers` as indexed positions, all a depth-only pass needs: each
/// vertex is fetched and transformed once per draw instead of once per corner (a reconstruction
/// shares each vertex among about six triangles; the shadow pass draws it once per light view).
struct ScenePositions {
  std::optional<vk::VulkanBuffer> positions, indices;
  std::uint32_t index_count = 0;
};
/// `meshes` must be valid (MrScene::validate()).
void upload_scene_positions(vk::VulkanContext& context, std::span<const TriangleMesh> meshes, MeshLayers layers,
                            ScenePositions& positions);

/// Colour targets cleared and left in TRANSFER_SRC_OPTIMAL for a copy to a buffer; depth cleared
/// and discarded.
[[nodiscard]] vk::UniqueRenderPass create_raster_pass(VkDevice device, std::span<const VkFormat> colour_formats,
                                                      VkFormat depth_format);
[[nodiscard]] vk::UniqueFramebuffer create_framebuffer(VkDevice device, VkRenderPass pass,
                                                       std::span<const VkImageView> views, std::uint32_t width,
                                                       std::uint32_t height);

struct MeshPipeline {
  vk::UniqueShaderModule vertex_shader, fragment_shader;
  vk::UniquePipelineLayout layout;
  vk::UniquePipeline pipeline;
  std::uint32_t push_constant_bytes = 0;
};

struct MeshPipelineInfo {
  VkRenderPass render_pass = VK_NULL_HANDLE;
  std::span<const std::uint32_t> vertex_spirv;
  std::span<const std::uint32_t> fragment_spirv;
  std::uint32_t colour_targets = 1;
  std::uint32_t push_constant_bytes = 0;  ///< visible to both stages
  bool position_only = false;             ///< ScenePositions input: location 0, tightly packed
};

/// Triangles with RasterVertex input, depth test LESS, no culling (reconstructed meshes and open
/// models have no consistent winding), dynamic viewport and scissor.
[[nodiscard]] MeshPipeline create_mesh_pipeline(VkDevice device, const MeshPipelineInfo& info);

/// Binds `pipeline`, sets viewport + scissor to `area`, pushes `constants` and draws `vertices`.
void draw_scene(VkCommandBuffer cmd, const MeshPipeline& pipeline, const SceneVertices& vertices,
                std::span<const std::byte> constants, const VkRect2D& area);
/// The same for indexed positions (a position_only pipeline).
void draw_scene(VkCommandBuffer cmd, const MeshPipeline& pipeline, const ScenePositions& positions,
                std::span<const std::byte> constants, const VkRect2D& area);

}  // namespace relight::render::detail
