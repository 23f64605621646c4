// Vulkan method 1 (definition in normals_raw_depth.h, API in normals_raw_depth_vk.h).
#include <optional>
#include <vector>

#include "relight/core/error.h"
#include "relight/reconstruct/normals_blend_shared.h"
#include "relight/reconstruct/normals_raw_depth_vk.h"
#include "relight/shaders/normals_blend_comp.h"
#include "relight/shaders/normals_fill_holes_comp.h"
#include "relight/vk/buffer.h"
#include "relight/vk/compute_pipeline.h"
#include "relight/vk/context.h"
#include "relight/vk/timer.h"
#include "relight/vk/transfer.h"

namespace relight::reconstruct {

struct NormalsRawDepthVk::Pipelines {
  explicit Pipelines(vk::VulkanContext& context)
      : blend(context, {.spirv = shaders::normals_blend_comp,
                        .storage_buffers = 6,
                        .push_constant_bytes = sizeof(gpu::NormalsBlendParams),
                        .max_descriptor_sets = 4}),
        fill(context, {.spirv = shaders::normals_fill_holes_comp,
                       .storage_buffers = 3,
                       .push_constant_bytes = sizeof(gpu::NormalsFillParams),
                       .max_descriptor_sets = 4}),
        timer(context) {}
  vk::ComputePipeline blend;
  vk::ComputePipeline fill;
  vk::GpuTimer timer;
};

/// Device buffers kept across frames, remade only when a size changes: a steady run allocates
/// no device memory. The first group serves the device path, the second the host convenience.
struct NormalsRawDepthVk::Scratch {
  std::optional<vk::VulkanBuffer> unfilled, pyramid, curvature;
  std::optional<vk::VulkanBuffer> depth, positions, normals, previous_positions;
};

NormalsRawDepthVk::NormalsRawDepthVk(vk::VulkanContext& context)
    : context_(context),
      cross_(context),
      pipelines_(std::make_unique<Pipelines>(context)),
      scratch_(std::make_unique<Scratch>()) {}

NormalsRawDepthVk::~NormalsRawDepthVk() = default;

namespace {

void add_ms(std::optional<double>& total, std::optional<double> ms) {
  if (ms && total) *total += *ms;
}

}  // namespace

std::optional<double> NormalsRawDepthVk::run(const vk::VulkanBuffer& depth, int width, int height,
                                             const PinholeIntrinsics& intrinsics, const Pose& camera_to_world,
                                             const NormalsDeviceHistory* previous,
                                             const NormalsRawDepthOptions& options, vk::VulkanBuffer& positions,
                                             vk::VulkanBuffer& normals) {
  last_gpu_ms_.reset();
  if (width <= 0 || height <= 0) return last_gpu_ms_;
  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  const std::size_t map_bytes = pixels * sizeof(Float3);
  if (positions.size_bytes() < map_bytes || normals.size_bytes() < map_bytes) {
    throw LogicError("NormalsRawDepthVk::run: output buffers smaller than width*height Float3");
  }
  Scratch& scratch = *scratch_;
  const bool usable_history = previous && previous->normals.width() == width && previous->normals.height() == height &&
                              previous->positions.size_bytes() >= map_bytes;
  // One scratch map, `unfilled`, holds the normals before hole filling, which reads it and writes
  // the output. With history the cross products go to the output first and the blend writes
  // `unfilled`; without, the blend is the identity and the cross products go to `unfilled`
  // directly. (Three maps in flight, not four: on a CPU device the cache footprint is the cost.)
  vk::VulkanBuffer& unfilled = vk::buffer_of_size(scratch.unfilled, context_, map_bytes);
  std::optional<double> total = cross_.run(depth, positions, usable_history ? normals : unfilled, width, height,
                                           intrinsics, cross_normal_options(options));
  if (usable_history) {
    const std::vector<NormalsPyramidLevel> pyramid =
        normals_history_pyramid(previous->normals, options.mip_levels, options.threads);
    std::vector<Float3> texels;
    for (const auto& level : pyramid)
      texels.insert(texels.end(), level.normal.pixels().begin(), level.normal.pixels().end());
    vk::VulkanBuffer& pyramid_buffer = vk::buffer_of_size(scratch.pyramid, context_, texels.size() * sizeof(Float3));
    vk::VulkanBuffer& curvature_buffer =
        vk::buffer_of_size(scratch.curvature, context_, pyramid.front().curvature.bytes().size());
    vk::VulkanTransfer& transfer = context_.transfer();
    transfer.upload(std::as_bytes(std::span<const Float3>(texels)), pyramid_buffer);
    transfer.upload(pyramid.front().curvature.bytes(), curvature_buffer);

    // The same float matrices as the CPU's Rigid (pose in double, rounded per element).
    const Pose prev_from_current = previous->camera_to_world.inverse() * camera_to_world;
    const Pose current_from_prev = prev_from_current.inverse();
    gpu::NormalsBlendParams params{};
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c) params.prev_from_current[r * 4 + c] = static_cast<float>(prev_from_current.matrix()(r, c));
      for (int c = 0; c < 3; ++c) params.current_from_prev[r * 3 + c] = static_cast<float>(current_from_prev.matrix()(r, c));
    }
    params.fx = static_cast<float>(intrinsics.fx);
    params.fy = static_cast<float>(intrinsics.fy);
    params.cx = static_cast<float>(intrinsics.cx);
    params.cy = static_cast<float>(intrinsics.cy);
    params.blend_base = options.blend_base;
    params.disocclusion_m = options.disocclusion_m;
    params.width = static_cast<gpu::uint>(width);
    params.height = static_cast<gpu::uint>(height);
    params.levels = static_cast<gpu::uint>(pyramid.size());
    constexpr std::uint32_t local = RELIGHT_NORMALS_BLEND_LOCAL_SIZE;
    const auto set = pipelines_->blend.bind(
        {&positions, &normals, &previous->positions, &pyramid_buffer, &curvature_buffer, &unfilled});
    context_.submit([&](VkCommandBuffer cmd) {
      pipelines_->timer.start(cmd);
      pipelines_->blend.dispatch(cmd, set, params, vk::ComputePipeline::group_count(params.width, local),
                                 vk::ComputePipeline::group_count(params.height, local));
      pipelines_->timer.stop(cmd);
    });
    add_ms(total, pipelines_->timer.elapsed_ms());
  }

  // Fill reads `unfilled` and writes the output, so no pixel sees a neighbour's fill.
  const gpu::NormalsFillParams fill_params{static_cast<gpu::uint>(width), static_cast<gpu::uint>(height)};
  constexpr std::uint32_t local = RELIGHT_NORMALS_BLEND_LOCAL_SIZE;
  const auto fill_set = pipelines_->fill.bind({&positions, &unfilled, &normals});
  context_.submit([&](VkCommandBuffer cmd) {
    pipelines_->timer.start(cmd);
    pipelines_->fill.dispatch(cmd, fill_set, fill_params, vk::ComputePipeline::group_count(fill_params.width, local),
                              vk::ComputePipeline::group_count(fill_params.height, local));
    pipelines_->timer.stop(cmd);
  });
  add_ms(total, pipelines_->timer.elapsed_ms());
  last_gpu_ms_ = total;
  return last_gpu_ms_;
}

void NormalsRawDepthVk::run(const DepthMap& depth, const PinholeIntrinsics& intrinsics, const Pose& camera_to_world,
                            const NormalsHistory* previous, const NormalsRawDepthOptions& options,
                            PositionMap& positions, NormalMap& normals) {
  const int width = depth.width(), height = depth.height();
  positions.resize(width, height);
  normals.resize(width, height);
  last_gpu_ms_.reset();
  if (depth.empty()) return;
  const std::size_t map_bytes = positions.bytes().size();
  vk::VulkanTransfer& transfer = context_.transfer();
  Scratch& scratch = *scratch_;
  vk::VulkanBuffer& depth_buffer = vk::buffer_of_size(scratch.depth, context_, depth.bytes().size());
  vk::VulkanBuffer& position_buffer = vk::buffer_of_size(scratch.positions, context_, map_bytes);
  vk::VulkanBuffer& normal_buffer = vk::buffer_of_size(scratch.normals, context_, map_bytes);
  transfer.upload(depth.bytes(), depth_buffer);
  std::optional<NormalsDeviceHistory> history;
  if (previous && previous->normals.same_shape(depth) && previous->positions.same_shape(depth)) {
    vk::VulkanBuffer& previous_positions = vk::buffer_of_size(scratch.previous_positions, context_, map_bytes);
    transfer.upload(previous->positions.bytes(), previous_positions);
    history.emplace(NormalsDeviceHistory{previous->normals, previous_positions, previous->camera_to_world});
  }
  run(depth_buffer, width, height, intrinsics, camera_to_world, history ? &*history : nullptr, options, position_buffer,
      normal_buffer);
  transfer.download(position_buffer, positions.bytes());
  transfer.download(normal_buffer, normals.bytes());
}

void NormalsRawDepthVkStage::run(StageContext& context) {
  auto& depth = context.device_read<vk::VulkanBuffer>(depth_);
  // Only the shape is needed on the host; shape_of never downloads device-side pixels.
  const DepthMap& depth_shape = context.shape_of(depth_);
  const int width = depth_shape.width(), height = depth_shape.height();
  auto& positions =
      context.device_write<vk::VulkanBuffer>(positions_, [&](PositionMap& p) { p.resize(width, height); });
  auto& normals = context.device_write<vk::VulkanBuffer>(normals_, [&](NormalMap& n) { n.resize(width, height); });
  // The previous normals on the host for pass 1's pyramid; the previous positions on the device.
  std::optional<NormalsDeviceHistory> history;
  const PositionMap* previous_positions_shape = context.shape_of(previous_positions_);
  if (const NormalMap* previous_normals = context.get(previous_normals_);
      previous_normals && previous_positions_shape && previous_positions_shape->same_shape(depth_shape)) {
    if (const auto* previous_positions = context.device_read<vk::VulkanBuffer>(previous_positions_)) {
      history.emplace(NormalsDeviceHistory{*previous_normals, *previous_positions, previous_camera_to_world(context)});
    }
  }
  const std::optional<double> gpu_ms =
      method_.run(depth, width, height, context.get(frame_).intrinsics, camera_to_world(context),
                  history ? &*history : nullptr, options(), positions, normals);
  if (gpu_ms) context.report_device_ms(*gpu_ms);
}

std::unique_ptr<Stage> make_normals_raw_depth_stage(Backend backend, vk::VulkanContext* context,
                                                    NormalsRawDepthOptions options, NormalsDepthInput input) {
  return make_stage_for_backend<NormalsRawDepthCpuStage, NormalsRawDepthVkStage>(
      backend, context, "make_normals_raw_depth_stage", options, input);
}

}  // namespace relight::reconstruct
