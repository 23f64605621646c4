// Hierarchical warping on Vulkan (hierarchical_warp_vk.h): a pyramid dispatch per three levels,
// a barrier between dispatches, one descent dispatch, all in one submission.
#include "relight/render/vpl/hierarchical_warp_vk.h"

#include <algorithm>
#include <bit>
#include <string>

#include "relight/core/error.h"
#include "relight/render/vpl/hierarchical_warp_shared.h"
#include "relight/shaders/warp_descend_comp.h"
#include "relight/shaders/warp_pyramid_comp.h"
#include "relight/vk/barrier.h"
#include "relight/vk/buffer.h"
#include "relight/vk/compute_pipeline.h"
#include "relight/vk/context.h"
#include "relight/vk/timer.h"
#include "relight/vk/transfer.h"

namespace relight::render {
namespace {

constexpr std::uint32_t kLocal = RELIGHT_WARP_LOCAL_SIZE;
static_assert(sizeof(WarpPoint) == 2 * sizeof(float) && sizeof(WarpedTexel) == 3 * sizeof(std::uint32_t),
              "points and samples are copied to and from the device as packed words");

std::size_t pyramid_floats(std::uint32_t size) {
  std::size_t floats = 0;
  for (std::size_t side = size; side >= 1; side /= 2) floats += side * side;
  return floats;
}

}  // namespace

struct HierarchicalWarpVk::Pipelines {
  explicit Pipelines(vk::VulkanContext& context)
      : pyramid(context, {.spirv = shaders::warp_pyramid_comp, .storage_buffers = 2,
                          .push_constant_bytes = sizeof(gpu::WarpPyramidParams), .max_descriptor_sets = 2}),
        descend(context, {.spirv = shaders::warp_descend_comp, .storage_buffers = 3,
                          .push_constant_bytes = sizeof(gpu::WarpDescendParams), .max_descriptor_sets = 2}),
        timer(context) {}
  vk::ComputePipeline pyramid;
  vk::ComputePipeline descend;
  vk::GpuTimer timer;
  std::unique_ptr<vk::VulkanBuffer> sums;
};

HierarchicalWarpVk::HierarchicalWarpVk(vk::VulkanContext& context)
    : context_(context), pipelines_(std::make_unique<Pipelines>(context)) {}

HierarchicalWarpVk::~HierarchicalWarpVk() = default;

std::optional<double> HierarchicalWarpVk::run(const vk::VulkanBuffer& importance, int size,
                                              const vk::VulkanBuffer& points, std::uint32_t count,
                                              vk::VulkanBuffer& samples) {
  if (size < 1 || size > ImportancePyramid::kMaxSize || !std::has_single_bit(static_cast<unsigned>(size)))
    throw LogicError("HierarchicalWarpVk::run: side " + std::to_string(size) + " is not a power of two in range");
  const auto side = static_cast<std::uint32_t>(size);
  if (importance.size_bytes() < std::size_t{side} * side * sizeof(float) ||
      points.size_bytes() < std::size_t{count} * 2 * sizeof(float) ||
      samples.size_bytes() < std::size_t{count} * 3 * sizeof(std::uint32_t))
    throw LogicError("HierarchicalWarpVk::run: buffers smaller than the map or the point count");
  const std::size_t floats = pyramid_floats(side);
  Pipelines& p = *pipelines_;
  if (!p.sums || p.sums->size_bytes() != floats * sizeof(float))
    p.sums = std::make_unique<vk::VulkanBuffer>(context_, floats * sizeof(float));
  const auto levels = static_cast<std::uint32_t>(std::countr_zero(side)) + 1;
  const auto pyramid_set = p.pyramid.bind({&importance, p.sums.get()});
  const auto descend_set = p.descend.bind({p.sums.get(), &points, &samples});
  context_.submit([&](VkCommandBuffer cmd) {
    p.timer.start(cmd);
    if (levels == 1)  // a 1x1 map: only its copy into level 0
      p.pyramid.dispatch(cmd, pyramid_set, gpu::WarpPyramidParams{0, 1, 0, 0, {0, 0, 0, 0}}, 1, 1);
    std::uint32_t fine_level = 0, fine_offset = 0;
    while (fine_level + 1 < levels) {
      gpu::WarpPyramidParams params{fine_level == 0 ? 0u : 1u, side >> fine_level, fine_offset, 0, {0, 0, 0, 0}};
      params.level_count = std::min<std::uint32_t>(RELIGHT_WARP_LEVELS_PER_DISPATCH, levels - 1 - fine_level);
      std::uint32_t offset = fine_offset + params.fine_side * params.fine_side;
      for (std::uint32_t i = 0; i < params.level_count; ++i) {
        params.offsets[i] = offset;
        const std::uint32_t level_side = side >> (fine_level + 1 + i);
        offset += level_side * level_side;
      }
      if (fine_level > 0) vk::compute_barrier(cmd);
      const std::uint32_t blocks = params.fine_side >> params.level_count;
      const std::uint32_t groups = vk::ComputePipeline::group_count(blocks, RELIGHT_WARP_PYRAMID_GROUP);
      p.pyramid.dispatch(cmd, pyramid_set, params, groups, groups);
      fine_level += params.level_count;
      fine_offset = params.offsets[params.level_count - 1];
    }
    vk::compute_barrier(cmd);
    if (count > 0)
      p.descend.dispatch(cmd, descend_set, gpu::WarpDescendParams{side, levels, count, 0},
                         vk::ComputePipeline::group_count(count, kLocal), 1);
    p.timer.stop(cmd);
  });
  return p.timer.elapsed_ms();
}

std::vector<WarpedTexel> HierarchicalWarpVk::warp(std::span<const float> importance, int size,
                                                  std::span<const WarpPoint> points) {
  const ImportancePyramid checked(importance, size);  // the input checks, and the total
  if (!(checked.total() > 0.f)) return {};
  const auto count = static_cast<std::uint32_t>(points.size());
  vk::VulkanTransfer& transfer = context_.transfer();
  vk::VulkanBuffer importance_buffer(context_, importance.size_bytes());
  vk::VulkanBuffer point_buffer(context_, points.size_bytes());
  vk::VulkanBuffer sample_buffer(context_, std::size_t{count} * sizeof(WarpedTexel));
  transfer.upload(std::as_bytes(importance), importance_buffer);
  if (count > 0) transfer.upload(std::as_bytes(points), point_buffer);
  run(importance_buffer, size, point_buffer, count, sample_buffer);
  std::vector<WarpedTexel> samples(count);
  if (count > 0) transfer.download(sample_buffer, std::as_writable_bytes(std::span(samples)));
  return samples;
}

std::vector<float> HierarchicalWarpVk::download_pyramid() const {
  if (!pipelines_->sums) return {};
  std::vector<float> sums(pipelines_->sums->size_bytes() / sizeof(float));
  context_.transfer().download(*pipelines_->sums, std::as_writable_bytes(std::span(sums)));
  return sums;
}

}  // namespace relight::render
