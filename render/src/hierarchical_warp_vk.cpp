// Hierarchical warping on Vulkan (hierarchical_warp_vk.h): a pyramid dispatch per level, a
// barrier between levels, one descent dispatch, all in one submission.
#include "relight/render/hierarchical_warp_vk.h"

#include <algorithm>
#include <bit>
#include <string>

#include "relight/core/error.h"
#include "relight/render/hierarchical_warp_shared.h"
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

/// Groups for `items` invocations of warp_pyramid.comp, as a 2-D grid where one row would be too long.
void dispatch_items(VkCommandBuffer cmd, const vk::ComputePipeline& pipeline, const vk::UniqueDescriptorSet& set,
                    const gpu::WarpPyramidParams& params, std::uint32_t items) {
  constexpr std::uint32_t kMaxRow = 32768;
  const std::uint32_t groups = vk::ComputePipeline::group_count(items, kLocal);
  const std::uint32_t x = std::max(std::min(groups, kMaxRow), 1u);
  pipeline.dispatch(cmd, set, params, x, vk::ComputePipeline::group_count(groups, x));
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
    dispatch_items(cmd, p.pyramid, pyramid_set, {0, side, 0, 0}, side * side);
    std::uint32_t fine_offset = 0;
    for (std::uint32_t level = 1; level < levels; ++level) {
      const std::uint32_t coarse_side = side >> level, fine_side = coarse_side * 2;
      const std::uint32_t coarse_offset = fine_offset + fine_side * fine_side;
      vk::compute_barrier(cmd);
      dispatch_items(cmd, p.pyramid, pyramid_set, {1, coarse_side, fine_offset, coarse_offset},
                     coarse_side * coarse_side);
      fine_offset = coarse_offset;
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
