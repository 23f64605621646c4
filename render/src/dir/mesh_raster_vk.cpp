#include "dir/mesh_raster_vk.h"

#include <algorithm>
#include <array>
#include <vector>

#include "relight/vk/check.h"
#include "relight/vk/context.h"
#include "relight/vk/storage_buffer_sets.h"  // create_shader_module

namespace relight::render::detail {
namespace {

bool in_layers(const TriangleMesh& mesh, MeshLayers layers) {
  return layers == MeshLayers::All || mesh.real == (layers == MeshLayers::Real);
}

}  // namespace

void upload_scene_vertices(vk::VulkanContext& context, const MrScene& scene, MeshLayers layers, SceneVertices& out) {
  scene.validate();
  std::size_t vertex_count = 0, index_count = 0;
  for (const TriangleMesh& mesh : scene.meshes) {
    if (!in_layers(mesh, layers)) continue;
    vertex_count += mesh.normals.empty() ? 3 * mesh.triangles.size() : mesh.positions.size();
    index_count += 3 * mesh.triangles.size();
  }
  std::vector<RasterVertex> vertices;
  std::vector<std::uint32_t> indices;
  vertices.reserve(vertex_count);  // a reconstruction's 300k vertices: no regrowth (and its copies) every frame
  indices.reserve(index_count);
  std::vector<bool> provoking;  // per vertex of the mesh: first corner of a triangle already, its info set
  for (const TriangleMesh& mesh : scene.meshes) {
    if (!in_layers(mesh, layers)) continue;
    const bool textured = !mesh.texcoords.empty();
    const auto vertex = [&](std::uint32_t v, const Eigen::Vector3f& n, std::uint32_t info) {
      const Eigen::Vector3f& p = mesh.positions[v];
      const Eigen::Vector2f uv = textured ? mesh.texcoords[v] : Eigen::Vector2f::Zero();
      return RasterVertex{{p.x(), p.y(), p.z()}, {n.x(), n.y(), n.z()}, info, {uv.x(), uv.y()}};
    };
    const auto info_of = [&](std::size_t t) {
      return mesh.triangle_material[t] | (mesh.real ? 0u : kVirtualBit) | (textured ? kTexcoordBit : 0u);
    };
    if (mesh.normals.empty()) {
      for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
        const auto& tri = mesh.triangles[t];
        const Eigen::Vector3f flat = (mesh.positions[tri[1]] - mesh.positions[tri[0]])
                                         .cross(mesh.positions[tri[2]] - mesh.positions[tri[0]])
                                         .normalized();
        for (std::uint32_t v : tri) {
          indices.push_back(static_cast<std::uint32_t>(vertices.size()));
          vertices.push_back(vertex(v, flat, info_of(t)));
        }
      }
      continue;
    }
    const auto base = static_cast<std::uint32_t>(vertices.size());
    for (std::uint32_t v = 0; v < mesh.positions.size(); ++v) vertices.push_back(vertex(v, mesh.normals[v], 0u));
    provoking.assign(mesh.positions.size(), false);
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
      const auto& tri = mesh.triangles[t];
      const std::uint32_t info = info_of(t);
      std::uint32_t first = base + tri[0];
      if (!provoking[tri[0]]) {
        provoking[tri[0]] = true;
        vertices[first].info = info;
      } else if (vertices[first].info != info) {
        RasterVertex copy = vertices[first];
        copy.info = info;
        first = static_cast<std::uint32_t>(vertices.size());
        vertices.push_back(copy);
      }
      indices.insert(indices.end(), {first, base + tri[1], base + tri[2]});
    }
  }
  vk::reserve_with_headroom(out.buffer, context, std::max<std::size_t>(4, vertices.size() * sizeof(RasterVertex)),
                            vk::BufferDomain::Upload, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
  vk::reserve_with_headroom(out.indices, context, std::max<std::size_t>(4, indices.size() * sizeof(std::uint32_t)),
                            vk::BufferDomain::Upload, VK_BUFFER_USAGE_INDEX_BUFFER_BIT);
  if (!vertices.empty()) out.buffer->write(std::as_bytes(std::span(vertices)));
  if (!indices.empty()) out.indices->write(std::as_bytes(std::span(indices)));
  out.index_count = static_cast<std::uint32_t>(indices.size());
}

void upload_scene_positions(vk::VulkanContext& context, std::span<const TriangleMesh> meshes, MeshLayers layers,
                            ScenePositions& out) {
  std::size_t vertex_count = 0, index_count = 0;
  for (const TriangleMesh& mesh : meshes) {
    if (!in_layers(mesh, layers)) continue;
    vertex_count += mesh.positions.size();
    index_count += 3 * mesh.triangles.size();
  }
  std::vector<float> positions;
  std::vector<std::uint32_t> indices;
  positions.reserve(3 * vertex_count);
  indices.reserve(index_count);
  for (const TriangleMesh& mesh : meshes) {
    if (!in_layers(mesh, layers)) continue;
    const auto base = static_cast<std::uint32_t>(positions.size() / 3);
    for (const Eigen::Vector3f& p : mesh.positions) positions.insert(positions.end(), {p.x(), p.y(), p.z()});
    for (const auto& tri : mesh.triangles)
      for (std::uint32_t v : tri) indices.push_back(base + v);
  }
  vk::reserve_with_headroom(out.positions, context, std::max<std::size_t>(4, positions.size() * sizeof(float)),
                            vk::BufferDomain::Upload, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
  vk::reserve_with_headroom(out.indices, context, std::max<std::size_t>(4, indices.size() * sizeof(std::uint32_t)),
                            vk::BufferDomain::Upload, VK_BUFFER_USAGE_INDEX_BUFFER_BIT);
  if (!positions.empty()) out.positions->write(std::as_bytes(std::span(positions)));
  if (!indices.empty()) out.indices->write(std::as_bytes(std::span(indices)));
  out.index_count = static_cast<std::uint32_t>(indices.size());
}

vk::UniqueRenderPass create_raster_pass(VkDevice device, std::span<const VkFormat> colour_formats, VkFormat depth_format) {
  std::vector<VkAttachmentDescription> attachments;
  std::vector<VkAttachmentReference> colour;
  for (VkFormat format : colour_formats) {
    colour.push_back({static_cast<std::uint32_t>(attachments.size()), VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL});
    attachments.push_back({0, format, VK_SAMPLE_COUNT_1_BIT, VK_ATTACHMENT_LOAD_OP_CLEAR, VK_ATTACHMENT_STORE_OP_STORE,
                           VK_ATTACHMENT_LOAD_OP_DONT_CARE, VK_ATTACHMENT_STORE_OP_DONT_CARE, VK_IMAGE_LAYOUT_UNDEFINED,
                           VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL});
  }
  const VkAttachmentReference depth{static_cast<std::uint32_t>(attachments.size()),
                                    VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
  attachments.push_back({0, depth_format, VK_SAMPLE_COUNT_1_BIT, VK_ATTACHMENT_LOAD_OP_CLEAR,
                         VK_ATTACHMENT_STORE_OP_DONT_CARE, VK_ATTACHMENT_LOAD_OP_DONT_CARE,
                         VK_ATTACHMENT_STORE_OP_DONT_CARE, VK_IMAGE_LAYOUT_UNDEFINED,
                         VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL});
  VkSubpassDescription subpass{};
  subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  subpass.colorAttachmentCount = static_cast<std::uint32_t>(colour.size());
  subpass.pColorAttachments = colour.data();
  subpass.pDepthStencilAttachment = &depth;
  // Earlier copies out of the targets finish before the pass writes them; the pass's writes
  // finish before the copies that follow it.
  const std::array<VkSubpassDependency, 2> dependencies{{
      {VK_SUBPASS_EXTERNAL, 0, VK_PIPELINE_STAGE_TRANSFER_BIT,
       VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT,
       VK_ACCESS_TRANSFER_READ_BIT, VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, 0},
      {0, VK_SUBPASS_EXTERNAL, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
       VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT, VK_ACCESS_TRANSFER_READ_BIT, 0},
  }};
  VkRenderPassCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO;
  info.attachmentCount = static_cast<std::uint32_t>(attachments.size());
  info.pAttachments = attachments.data();
  info.subpassCount = 1;
  info.pSubpasses = &subpass;
  info.dependencyCount = static_cast<std::uint32_t>(dependencies.size());
  info.pDependencies = dependencies.data();
  VkRenderPass pass = VK_NULL_HANDLE;
  RELIGHT_VK_CHECK(vkCreateRenderPass(device, &info, nullptr, &pass));
  return vk::UniqueRenderPass(device, pass);
}

vk::UniqueFramebuffer create_framebuffer(VkDevice device, VkRenderPass pass, std::span<const VkImageView> views,
                                         std::uint32_t width, std::uint32_t height) {
  VkFramebufferCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO;
  info.renderPass = pass;
  info.attachmentCount = static_cast<std::uint32_t>(views.size());
  info.pAttachments = views.data();
  info.width = width;
  info.height = height;
  info.layers = 1;
  VkFramebuffer raw = VK_NULL_HANDLE;
  RELIGHT_VK_CHECK(vkCreateFramebuffer(device, &info, nullptr, &raw));
  return vk::UniqueFramebuffer(device, raw);
}

namespace {

vk::UniquePipelineLayout create_layout(VkDevice device, std::uint32_t push_constant_bytes) {
  const VkPushConstantRange push{VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0, push_constant_bytes};
  VkPipelineLayoutCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
  info.pushConstantRangeCount = push_constant_bytes > 0 ? 1 : 0;
  info.pPushConstantRanges = &push;
  VkPipelineLayout raw = VK_NULL_HANDLE;
  RELIGHT_VK_CHECK(vkCreatePipelineLayout(device, &info, nullptr, &raw));
  return vk::UniquePipelineLayout(device, raw);
}

}  // namespace

MeshPipeline create_mesh_pipeline(VkDevice device, const MeshPipelineInfo& info) {
  MeshPipeline out;
  out.vertex_shader = vk::create_shader_module(device, info.vertex_spirv);
  out.fragment_shader = vk::create_shader_module(device, info.fragment_spirv);
  out.layout = create_layout(device, info.push_constant_bytes);
  out.push_constant_bytes = info.push_constant_bytes;

  const std::array<VkPipelineShaderStageCreateInfo, 2> stages{{
      {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, nullptr, 0, VK_SHADER_STAGE_VERTEX_BIT,
       out.vertex_shader.get(), "main", nullptr},
      {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, nullptr, 0, VK_SHADER_STAGE_FRAGMENT_BIT,
       out.fragment_shader.get(), "main", nullptr},
  }};
  const VkVertexInputBindingDescription binding{0,
                                                info.position_only ? static_cast<std::uint32_t>(3 * sizeof(float))
                                                                   : static_cast<std::uint32_t>(sizeof(RasterVertex)),
                                                VK_VERTEX_INPUT_RATE_VERTEX};
  const std::array<VkVertexInputAttributeDescription, 4> attributes{{
      {0, 0, VK_FORMAT_R32G32B32_SFLOAT,
       info.position_only ? 0u : static_cast<std::uint32_t>(offsetof(RasterVertex, position))},
      {1, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(RasterVertex, normal)},
      {2, 0, VK_FORMAT_R32_UINT, offsetof(RasterVertex, info)},
      {3, 0, VK_FORMAT_R32G32_SFLOAT, offsetof(RasterVertex, texcoord)},
  }};
  VkPipelineVertexInputStateCreateInfo vertex_input{};
  vertex_input.sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO;
  vertex_input.vertexBindingDescriptionCount = 1;
  vertex_input.pVertexBindingDescriptions = &binding;
  vertex_input.vertexAttributeDescriptionCount = info.position_only ? 1u : static_cast<std::uint32_t>(attributes.size());
  vertex_input.pVertexAttributeDescriptions = attributes.data();
  VkPipelineInputAssemblyStateCreateInfo assembly{};
  assembly.sType = VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO;
  assembly.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
  VkPipelineViewportStateCreateInfo viewport_state{};
  viewport_state.sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO;
  viewport_state.viewportCount = 1;
  viewport_state.scissorCount = 1;
  const std::array<VkDynamicState, 2> dynamic{VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
  VkPipelineDynamicStateCreateInfo dynamic_state{};
  dynamic_state.sType = VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO;
  dynamic_state.dynamicStateCount = static_cast<std::uint32_t>(dynamic.size());
  dynamic_state.pDynamicStates = dynamic.data();
  VkPipelineRasterizationStateCreateInfo raster{};
  raster.sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO;
  raster.polygonMode = VK_POLYGON_MODE_FILL;
  raster.cullMode = VK_CULL_MODE_NONE;
  raster.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
  raster.lineWidth = 1.f;
  VkPipelineMultisampleStateCreateInfo multisample{};
  multisample.sType = VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO;
  multisample.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
  VkPipelineDepthStencilStateCreateInfo depth{};
  depth.sType = VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO;
  depth.depthTestEnable = VK_TRUE;
  depth.depthWriteEnable = VK_TRUE;
  depth.depthCompareOp = VK_COMPARE_OP_LESS;
  std::vector<VkPipelineColorBlendAttachmentState> blend(info.colour_targets);
  for (auto& b : blend)
    b.colorWriteMask = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
  VkPipelineColorBlendStateCreateInfo colour_blend{};
  colour_blend.sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO;
  colour_blend.attachmentCount = static_cast<std::uint32_t>(blend.size());
  colour_blend.pAttachments = blend.data();

  VkGraphicsPipelineCreateInfo create{};
  create.sType = VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO;
  create.stageCount = static_cast<std::uint32_t>(stages.size());
  create.pStages = stages.data();
  create.pVertexInputState = &vertex_input;
  create.pInputAssemblyState = &assembly;
  create.pViewportState = &viewport_state;
  create.pRasterizationState = &raster;
  create.pMultisampleState = &multisample;
  create.pDepthStencilState = &depth;
  create.pColorBlendState = &colour_blend;
  create.pDynamicState = &dynamic_state;
  create.layout = out.layout.get();
  create.renderPass = info.render_pass;
  VkPipeline raw = VK_NULL_HANDLE;
  RELIGHT_VK_CHECK(vkCreateGraphicsPipelines(device, VK_NULL_HANDLE, 1, &create, nullptr, &raw));
  out.pipeline = vk::UniquePipeline(device, raw);
  return out;
}

namespace {

/// Binds `pipeline` and `vertex_buffer` and sets the viewport, scissor and push constants of a
/// draw into `area`.
void begin_draw(VkCommandBuffer cmd, const MeshPipeline& pipeline, VkBuffer vertex_buffer,
                std::span<const std::byte> constants, const VkRect2D& area) {
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline.pipeline.get());
  const VkViewport viewport{static_cast<float>(area.offset.x), static_cast<float>(area.offset.y),
                            static_cast<float>(area.extent.width), static_cast<float>(area.extent.height), 0.f, 1.f};
  vkCmdSetViewport(cmd, 0, 1, &viewport);
  vkCmdSetScissor(cmd, 0, 1, &area);
  if (!constants.empty())
    vkCmdPushConstants(cmd, pipeline.layout.get(), VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
                       static_cast<std::uint32_t>(constants.size()), constants.data());
  const VkDeviceSize offset = 0;
  vkCmdBindVertexBuffers(cmd, 0, 1, &vertex_buffer, &offset);
}

void draw_indexed(VkCommandBuffer cmd, const MeshPipeline& pipeline, VkBuffer vertex_buffer, VkBuffer index_buffer,
                  std::uint32_t index_count, std::span<const std::byte> constants, const VkRect2D& area) {
  begin_draw(cmd, pipeline, vertex_buffer, constants, area);
  vkCmdBindIndexBuffer(cmd, index_buffer, 0, VK_INDEX_TYPE_UINT32);
  vkCmdDrawIndexed(cmd, index_count, 1, 0, 0, 0);
}

}  // namespace

void draw_scene(VkCommandBuffer cmd, const MeshPipeline& pipeline, const SceneVertices& vertices,
                std::span<const std::byte> constants, const VkRect2D& area) {
  if (vertices.index_count == 0) return;
  draw_indexed(cmd, pipeline, vertices.buffer->handle(), vertices.indices->handle(), vertices.index_count, constants,
               area);
}

void draw_scene(VkCommandBuffer cmd, const MeshPipeline& pipeline, const ScenePositions& positions,
                std::span<const std::byte> constants, const VkRect2D& area) {
  if (positions.index_count == 0) return;
  draw_indexed(cmd, pipeline, positions.positions->handle(), positions.indices->handle(), positions.index_count,
               constants, area);
}

}  // namespace relight::render::detail
