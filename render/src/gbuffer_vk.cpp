#include "relight/render/gbuffer_vk.h"

#include <array>
#include <cstring>
#include <vector>

#include "relight/core/error.h"
#include "relight/shaders/gbuffer_frag.h"
#include "relight/shaders/gbuffer_vert.h"
#include "relight/vk/buffer.h"
#include "relight/vk/check.h"
#include "relight/vk/context.h"
#include "relight/vk/image.h"
#include "relight/vk/storage_buffer_sets.h"  // create_shader_module
#include "relight/vk/timer.h"

namespace relight::render {
namespace {

constexpr VkFormat kTargetFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;
constexpr float kNear = 0.02f;
constexpr float kFar = 200.f;

struct Vertex {
  float position[3];
  float normal[3];
  std::uint32_t info;  // material index | virtual << 31
};

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

vk::UniqueRenderPass create_render_pass(VkDevice device) {
  std::array<VkAttachmentDescription, 3> attachments{};
  for (int i = 0; i < 2; ++i) {
    attachments[static_cast<std::size_t>(i)] = {0, kTargetFormat, VK_SAMPLE_COUNT_1_BIT, VK_ATTACHMENT_LOAD_OP_CLEAR,
                                                VK_ATTACHMENT_STORE_OP_STORE, VK_ATTACHMENT_LOAD_OP_DONT_CARE,
                                                VK_ATTACHMENT_STORE_OP_DONT_CARE, VK_IMAGE_LAYOUT_UNDEFINED,
                                                VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL};
  }
  attachments[2] = {0, kDepthFormat, VK_SAMPLE_COUNT_1_BIT, VK_ATTACHMENT_LOAD_OP_CLEAR, VK_ATTACHMENT_STORE_OP_DONT_CARE,
                    VK_ATTACHMENT_LOAD_OP_DONT_CARE, VK_ATTACHMENT_STORE_OP_DONT_CARE, VK_IMAGE_LAYOUT_UNDEFINED,
                    VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
  const std::array<VkAttachmentReference, 2> colour{{{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL},
                                                     {1, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL}}};
  const VkAttachmentReference depth{2, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
  VkSubpassDescription subpass{};
  subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  subpass.colorAttachmentCount = 2;
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

}  // namespace

struct GBufferVk::Impl {
  Impl(vk::VulkanContext& context, int width, int height);
  void create_pipeline();

  vk::VulkanContext& context;
  std::uint32_t width, height;
  vk::UniqueRenderPass render_pass;
  vk::VulkanImage position_target, normal_target, depth_target;
  vk::UniqueFramebuffer framebuffer;
  vk::UniqueShaderModule vertex_shader, fragment_shader;
  vk::UniquePipelineLayout layout;
  vk::UniquePipeline pipeline;
  vk::VulkanBuffer readback;
  vk::GpuTimer timer;
  std::unique_ptr<vk::VulkanBuffer> vertices;
  std::uint32_t vertex_count = 0;
  double gpu_ms = 0.0;
};

GBufferVk::Impl::Impl(vk::VulkanContext& context, int width, int height)
    : context(context),
      width(static_cast<std::uint32_t>(width)),
      height(static_cast<std::uint32_t>(height)),
      render_pass(create_render_pass(context.device())),
      position_target(context, this->width, this->height, kTargetFormat,
                      VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT),
      normal_target(context, this->width, this->height, kTargetFormat,
                    VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT),
      depth_target(context, this->width, this->height, kDepthFormat, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT,
                   VK_IMAGE_ASPECT_DEPTH_BIT),
      readback(context, 2ull * this->width * this->height * 4 * sizeof(float), vk::BufferDomain::Readback),
      timer(context) {
  const std::array<VkImageView, 3> views{position_target.view(), normal_target.view(), depth_target.view()};
  VkFramebufferCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO;
  info.renderPass = render_pass.get();
  info.attachmentCount = static_cast<std::uint32_t>(views.size());
  info.pAttachments = views.data();
  info.width = this->width;
  info.height = this->height;
  info.layers = 1;
  VkFramebuffer raw = VK_NULL_HANDLE;
  RELIGHT_VK_CHECK(vkCreateFramebuffer(context.device(), &info, nullptr, &raw));
  framebuffer = vk::UniqueFramebuffer(context.device(), raw);
  create_pipeline();
}

void GBufferVk::Impl::create_pipeline() {
  const VkDevice device = context.device();
  vertex_shader = vk::create_shader_module(device, shaders::gbuffer_vert);
  fragment_shader = vk::create_shader_module(device, shaders::gbuffer_frag);
  const VkPushConstantRange push{VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof(CameraConstants)};
  VkPipelineLayoutCreateInfo layout_info{};
  layout_info.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
  layout_info.pushConstantRangeCount = 1;
  layout_info.pPushConstantRanges = &push;
  VkPipelineLayout raw_layout = VK_NULL_HANDLE;
  RELIGHT_VK_CHECK(vkCreatePipelineLayout(device, &layout_info, nullptr, &raw_layout));
  layout = vk::UniquePipelineLayout(device, raw_layout);

  std::array<VkPipelineShaderStageCreateInfo, 2> stages{};
  stages[0] = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, nullptr, 0, VK_SHADER_STAGE_VERTEX_BIT,
               vertex_shader.get(), "main", nullptr};
  stages[1] = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, nullptr, 0, VK_SHADER_STAGE_FRAGMENT_BIT,
               fragment_shader.get(), "main", nullptr};
  const VkVertexInputBindingDescription binding{0, sizeof(Vertex), VK_VERTEX_INPUT_RATE_VERTEX};
  const std::array<VkVertexInputAttributeDescription, 3> attributes{{
      {0, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, position)},
      {1, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, normal)},
      {2, 0, VK_FORMAT_R32_UINT, offsetof(Vertex, info)},
  }};
  VkPipelineVertexInputStateCreateInfo vertex_input{};
  vertex_input.sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO;
  vertex_input.vertexBindingDescriptionCount = 1;
  vertex_input.pVertexBindingDescriptions = &binding;
  vertex_input.vertexAttributeDescriptionCount = static_cast<std::uint32_t>(attributes.size());
  vertex_input.pVertexAttributeDescriptions = attributes.data();
  VkPipelineInputAssemblyStateCreateInfo assembly{};
  assembly.sType = VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO;
  assembly.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
  const VkViewport viewport{0.f, 0.f, static_cast<float>(width), static_cast<float>(height), 0.f, 1.f};
  const VkRect2D scissor{{0, 0}, {width, height}};
  VkPipelineViewportStateCreateInfo viewport_state{};
  viewport_state.sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO;
  viewport_state.viewportCount = 1;
  viewport_state.pViewports = &viewport;
  viewport_state.scissorCount = 1;
  viewport_state.pScissors = &scissor;
  VkPipelineRasterizationStateCreateInfo raster{};
  raster.sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO;
  raster.polygonMode = VK_POLYGON_MODE_FILL;
  raster.cullMode = VK_CULL_MODE_NONE;  // reconstructed meshes and open models have no consistent winding
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
  std::array<VkPipelineColorBlendAttachmentState, 2> blend{};
  for (auto& b : blend)
    b.colorWriteMask = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
  VkPipelineColorBlendStateCreateInfo colour_blend{};
  colour_blend.sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO;
  colour_blend.attachmentCount = static_cast<std::uint32_t>(blend.size());
  colour_blend.pAttachments = blend.data();

  VkGraphicsPipelineCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO;
  info.stageCount = static_cast<std::uint32_t>(stages.size());
  info.pStages = stages.data();
  info.pVertexInputState = &vertex_input;
  info.pInputAssemblyState = &assembly;
  info.pViewportState = &viewport_state;
  info.pRasterizationState = &raster;
  info.pMultisampleState = &multisample;
  info.pDepthStencilState = &depth;
  info.pColorBlendState = &colour_blend;
  info.layout = layout.get();
  info.renderPass = render_pass.get();
  VkPipeline raw_pipeline = VK_NULL_HANDLE;
  RELIGHT_VK_CHECK(vkCreateGraphicsPipelines(device, VK_NULL_HANDLE, 1, &info, nullptr, &raw_pipeline));
  pipeline = vk::UniquePipeline(device, raw_pipeline);
}

GBufferVk::GBufferVk(vk::VulkanContext& context, int width, int height) {
  if (width <= 0 || height <= 0) throw Error("the G-buffer size must be positive");
  if (context.graphics_queue_family() != context.compute_queue_family())
    throw Error("Vulkan device '" + context.device_info().name + "' has no queue for both graphics and compute");
  impl_ = std::make_unique<Impl>(context, width, height);
}

GBufferVk::~GBufferVk() = default;

double GBufferVk::last_gpu_ms() const { return impl_->gpu_ms; }

void GBufferVk::set_scene(const MrScene& scene) {
  scene.validate();
  std::vector<Vertex> vertices;
  for (const TriangleMesh& mesh : scene.meshes) {
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
      const std::uint32_t info = mesh.triangle_material[t] | (mesh.real ? 0u : 0x80000000u);
      const auto& tri = mesh.triangles[t];
      Eigen::Vector3f flat = Eigen::Vector3f::Zero();
      if (mesh.normals.empty())  // flat shading: each triangle gets its own three vertices
        flat = (mesh.positions[tri[1]] - mesh.positions[tri[0]]).cross(mesh.positions[tri[2]] - mesh.positions[tri[0]]).normalized();
      for (std::uint32_t v : tri) {
        const Eigen::Vector3f& p = mesh.positions[v];
        const Eigen::Vector3f n = mesh.normals.empty() ? flat : mesh.normals[v];
        vertices.push_back({{p.x(), p.y(), p.z()}, {n.x(), n.y(), n.z()}, info});
      }
    }
  }
  // Expanded per corner: simple, and the G-buffer's cost is the rasterisation, not the vertex count.
  const auto upload = [&](const auto& data, VkBufferUsageFlags usage) {
    auto buffer = std::make_unique<vk::VulkanBuffer>(impl_->context, std::max<std::size_t>(4, data.size() * sizeof(data[0])),
                                                     vk::BufferDomain::Upload, usage);
    if (!data.empty()) buffer->write(std::as_bytes(std::span(data)));
    return buffer;
  };
  impl_->vertices = upload(vertices, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
  impl_->vertex_count = static_cast<std::uint32_t>(vertices.size());
}

GBuffer GBufferVk::render(const MrCamera& camera) {
  Impl& g = *impl_;
  if (!g.vertices) throw LogicError("GBufferVk::set_scene must come before render");
  if (camera.intrinsics.width != static_cast<int>(g.width) || camera.intrinsics.height != static_cast<int>(g.height))
    throw Error("GBufferVk: the camera's image size differs from the renderer's");
  CameraConstants constants{};
  const Eigen::Matrix4f clip = world_to_clip(camera);
  std::memcpy(constants.world_to_clip, clip.data(), sizeof constants.world_to_clip);
  const Eigen::Vector3f centre = camera.camera_to_world.translation().cast<float>();
  constants.centre[0] = centre.x();
  constants.centre[1] = centre.y();
  constants.centre[2] = centre.z();

  g.context.submit([&](VkCommandBuffer cmd) {
    std::array<VkClearValue, 3> clear{};
    clear[2].depthStencil = {1.f, 0};
    VkRenderPassBeginInfo begin{};
    begin.sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO;
    begin.renderPass = g.render_pass.get();
    begin.framebuffer = g.framebuffer.get();
    begin.renderArea = {{0, 0}, {g.width, g.height}};
    begin.clearValueCount = static_cast<std::uint32_t>(clear.size());
    begin.pClearValues = clear.data();
    g.timer.start(cmd);
    vkCmdBeginRenderPass(cmd, &begin, VK_SUBPASS_CONTENTS_INLINE);
    if (g.vertex_count > 0) {
      vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, g.pipeline.get());
      vkCmdPushConstants(cmd, g.layout.get(), VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
                         sizeof constants, &constants);
      const VkBuffer vertex_buffer = g.vertices->handle();
      const VkDeviceSize offset = 0;
      vkCmdBindVertexBuffers(cmd, 0, 1, &vertex_buffer, &offset);
      vkCmdDraw(cmd, g.vertex_count, 1, 0, 0);
    }
    vkCmdEndRenderPass(cmd);
    g.timer.stop(cmd);
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {g.width, g.height, 1};
    vkCmdCopyImageToBuffer(cmd, g.position_target.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, g.readback.handle(), 1, &region);
    region.bufferOffset = static_cast<VkDeviceSize>(g.width) * g.height * 4 * sizeof(float);
    vkCmdCopyImageToBuffer(cmd, g.normal_target.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, g.readback.handle(), 1, &region);
  });
  g.gpu_ms = g.timer.elapsed_ms().value_or(0.0);

  const std::size_t pixels = static_cast<std::size_t>(g.width) * g.height;
  std::vector<float> data(pixels * 8);
  g.readback.read(std::as_writable_bytes(std::span(data)));
  const int w = static_cast<int>(g.width), h = static_cast<int>(g.height);
  GBuffer out{PositionMap(w, h), NormalMap(w, h), LabelImage(w, h), Mask(w, h), DepthMap(w, h)};
  for (std::size_t i = 0; i < pixels; ++i) {
    const float* p = &data[4 * i];
    const float* n = &data[4 * (pixels + i)];
    if (p[3] == 0.f) continue;  // cleared: nothing drawn
    out.position.pixels()[i] = {p[0], p[1], p[2]};
    out.distance.pixels()[i] = std::abs(p[3]);
    out.virtual_surface.pixels()[i] = p[3] < 0.f ? 1 : 0;
    out.normal.pixels()[i] = {n[0], n[1], n[2]};
    out.material.pixels()[i] = static_cast<std::uint16_t>(n[3] + 1.f);
  }
  return out;
}

}  // namespace relight::render
