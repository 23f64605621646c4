#include "dir/ism_vk.h"

#include <algorithm>
#include <bit>
#include <vector>

#include "relight/core/error.h"
#include "relight/render/dir/shadow_maps.h"
#include "relight/shaders/ism_pull_push_comp.h"
#include "relight/shaders/ism_splat_comp.h"
#include "relight/vk/barrier.h"
#include "relight/vk/context.h"
#include "relight/vk/transfer.h"

namespace relight::render::detail {
namespace {

constexpr std::uint32_t kGroup = 64;

struct SplatParams {
  std::int32_t tile;
  std::uint32_t points_per_vpl, vpl_count, real_pool, virtual_pool, pad[3];
  float virtual_bounds[4];
  float scene_bounds[4];
};

struct PullPushParams {
  std::uint32_t mode, tiles, fine_size, fine_offset, coarse_offset, fine_is_atlas;
  std::uint32_t vpl_count, first_emitter;  ///< push: emitter tiles skip levels >= kEmitterPullPushLevels
};

/// Dispatches `items` invocations of a 1D shader that indexes by gl_GlobalInvocationID.y * row + x.
void dispatch_items(VkCommandBuffer cmd, const vk::ComputePipeline& pipeline, const vk::UniqueDescriptorSet& set,
                    const PullPushParams& params, std::uint32_t items) {
  constexpr std::uint32_t kMaxRow = 32768;
  const std::uint32_t groups = vk::ComputePipeline::group_count(items, kGroup);
  const std::uint32_t x = std::min(groups, kMaxRow);
  pipeline.dispatch(cmd, set, params, x, vk::ComputePipeline::group_count(groups, x));
}

}  // namespace

IsmVk::IsmVk(vk::VulkanContext& context)
    : context_(context),
      splat_(context, {.spirv = shaders::ism_splat_comp, .storage_buffers = 3, .push_constant_bytes = sizeof(SplatParams),
                       .max_descriptor_sets = 4}),
      pull_push_(context, {.spirv = shaders::ism_pull_push_comp, .storage_buffers = 2,
                           .push_constant_bytes = sizeof(PullPushParams), .max_descriptor_sets = 4}) {}

void IsmVk::set_points(const IsmPointPools& points) {
  std::vector<float> packed;
  for (const auto* pool : {&points.real, &points.virtual_points})
    for (const IsmPoint& p : *pool)
      packed.insert(packed.end(), {p.position.x(), p.position.y(), p.position.z(), p.half_size, p.normal.x(), p.normal.y(),
                                   p.normal.z(), 0.f});
  if (points.real.size() + points.virtual_points.size() > 2 * 65536u)
    throw Error("too many ISM points (at most 65536 per layer)");
  real_points_ = static_cast<std::uint32_t>(points.real.size());
  virtual_bounds_ = points.virtual_bounds;
  scene_bounds_ = points.scene_bounds;
  virtual_points_ = static_cast<std::uint32_t>(points.virtual_points.size());
  // The points change in number every frame.
  vk::reserve_with_headroom(points_, context_, std::max<std::size_t>(packed.size(), 8) * sizeof(float));
  if (!packed.empty()) context_.transfer().upload(std::as_bytes(std::span(packed)), *points_);
}

void IsmVk::ensure_buffers(std::size_t atlas_floats, std::size_t pyramid_floats) {
  atlas_floats = std::max<std::size_t>(atlas_floats, 1);
  pyramid_floats = std::max<std::size_t>(pyramid_floats, 1);
  if (atlas_ && atlas_->size_bytes() == atlas_floats * sizeof(float) && pyramid_ &&
      pyramid_->size_bytes() == pyramid_floats * sizeof(float))
    return;
  splat_set_ = {};
  pull_push_set_ = {};
  atlas_ = std::make_unique<vk::VulkanBuffer>(context_, atlas_floats * sizeof(float));
  pyramid_ = std::make_unique<vk::VulkanBuffer>(context_, pyramid_floats * sizeof(float));
  pull_push_set_ = pull_push_.bind({atlas_.get(), pyramid_.get()});
}

void IsmVk::record(VkCommandBuffer cmd, const vk::VulkanBuffer& vpls, std::uint32_t vpl_count,
                   std::uint32_t emitter_count, const IsmOptions& options) {
  if (!points_) throw LogicError("IsmVk::set_points must come before record");
  const auto tile = static_cast<std::uint32_t>(options.tile);
  const std::uint32_t tiles = 2 * vpl_count;
  std::vector<std::uint32_t> offsets{0};  // of levels 1.. in the pyramid
  for (int l = 1; l <= options.pull_push_levels; ++l) {
    const std::uint32_t size = tile >> l;
    offsets.push_back(offsets.back() + tiles * size * size);
  }
  ensure_buffers(static_cast<std::size_t>(tiles) * tile * tile, offsets.back());
  splat_set_ = {};  // the VPL buffer may be new: bind afresh (one small descriptor write)
  splat_set_ = splat_.bind({&*points_, &vpls, atlas_.get()});
  if (vpl_count == 0) return;
  vkCmdFillBuffer(cmd, atlas_->handle(), 0, VK_WHOLE_SIZE, std::bit_cast<std::uint32_t>(kShadowEmpty));
  vk::compute_barrier(cmd);
  const SplatParams splat{options.tile,
                          static_cast<std::uint32_t>(options.points_per_vpl),
                          vpl_count,
                          real_points_,
                          virtual_points_,
                          {0, 0, 0},
                          {virtual_bounds_.x(), virtual_bounds_.y(), virtual_bounds_.z(), virtual_bounds_.w()},
                          {scene_bounds_.x(), scene_bounds_.y(), scene_bounds_.z(), scene_bounds_.w()}};
  splat_.dispatch(cmd, splat_set_, splat, vk::ComputePipeline::group_count(splat.points_per_vpl, kGroup), vpl_count, 2);
  vk::compute_barrier(cmd);
  const int levels = options.pull_push_levels;
  // Level l (fine) and l + 1 (coarse); the push leaves emitter tiles' holes from level
  // kEmitterPullPushLevels on (ism.h), the pull ignores first_emitter.
  const auto level_params = [&](std::uint32_t mode, int l) {
    const std::uint32_t first_emitter = l >= kEmitterPullPushLevels ? vpl_count - emitter_count : vpl_count;
    return PullPushParams{mode,
                          tiles,
                          tile >> l,
                          l == 0 ? 0u : offsets[static_cast<std::size_t>(l - 1)],
                          offsets[static_cast<std::size_t>(l)],
                          l == 0 ? 1u : 0u,
                          vpl_count,
                          first_emitter};
  };
  for (int l = 0; l < levels; ++l) {  // pull: level l -> l + 1
    const std::uint32_t coarse = (tile >> l) / 2;
    dispatch_items(cmd, pull_push_, pull_push_set_, level_params(0, l), tiles * coarse * coarse);
    vk::compute_barrier(cmd);
  }
  for (int l = levels - 1; l >= 0; --l) {  // push: level l + 1 -> l
    const std::uint32_t fine = tile >> l;
    dispatch_items(cmd, pull_push_, pull_push_set_, level_params(1, l), tiles * fine * fine);
    vk::compute_barrier(cmd);
  }
}

}  // namespace relight::render::detail
