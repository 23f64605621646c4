// Vulkan version of hierarchical-warping importance sampling (importance_sampling.h): one
// dispatch per pyramid level (shaders/importance_pyramid.comp) and one for the warp
// (shaders/importance_warp.comp), recorded into a single submission with barriers between them.
#include "relight/core/error.h"
#include "relight/lights/importance_sampling.h"
#include "relight/lights/importance_shared.h"
#include "relight/shaders/importance_pyramid_comp.h"
#include "relight/shaders/importance_warp_comp.h"
#include "relight/vk/buffer.h"
#include "relight/vk/compute_pipeline.h"
#include "relight/vk/context.h"
#include "relight/vk/timer.h"
#include "relight/vk/transfer.h"

namespace relight::lights {

namespace {

void shader_write_to_read_barrier(VkCommandBuffer cmd) {
  VkMemoryBarrier barrier{};
  barrier.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
  barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
  barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1, &barrier,
                       0, nullptr, 0, nullptr);
}

}  // namespace

struct ImportanceSamplerVk::Resources {
  Resources(vk::VulkanContext& context, const ProbeGeometry& geometry)
      : pyramid_pipeline(context, {.spirv = shaders::importance_pyramid_comp,
                                   .storage_buffers = 3,
                                   .push_constant_bytes = sizeof(gpu::ImportancePyramidParams),
                                   .max_descriptor_sets = 2}),
        warp_pipeline(context, {.spirv = shaders::importance_warp_comp,
                                .storage_buffers = 4,
                                .push_constant_bytes = sizeof(gpu::ImportanceWarpParams),
                                .max_descriptor_sets = 2}),
        timer(context),
        levels(pyramid_levels(geometry.width(), geometry.height())),
        radiance(context, geometry.solid_angles().size() * sizeof(Float3)),
        solid_angle(context, geometry.solid_angles().size() * sizeof(float)),
        pyramid(context, pyramid_floats(levels) * sizeof(float)),
        pyramid_set(pyramid_pipeline.bind({&radiance, &solid_angle, &pyramid})) {
    context.transfer().upload(std::as_bytes(std::span(geometry.solid_angles())), solid_angle);
  }
  vk::ComputePipeline pyramid_pipeline;
  vk::ComputePipeline warp_pipeline;
  vk::GpuTimer timer;
  int levels;
  vk::VulkanBuffer radiance;
  vk::VulkanBuffer solid_angle;
  vk::VulkanBuffer pyramid;
  vk::UniqueDescriptorSet pyramid_set;
  std::optional<vk::VulkanBuffer> samples;  // grows with N
  vk::UniqueDescriptorSet warp_set;
};

ImportanceSamplerVk::ImportanceSamplerVk(vk::VulkanContext& context, const ProbeGeometry& geometry)
    : context_(context), geometry_(geometry), resources_(std::make_unique<Resources>(context, geometry)) {
  if (resources_->levels >= RELIGHT_IMPORTANCE_MAX_LEVELS) throw Error("light probe: image too large for the pyramid");
}

ImportanceSamplerVk::~ImportanceSamplerVk() = default;

LightSet ImportanceSamplerVk::run(const RadianceImage& probe, const ImportanceSamplingOptions& options,
                                  std::vector<WarpedSample>* samples_out) {
  if (options.samples <= 0) throw Error("light sampling: the number of lights must be positive");
  if (!probe.same_shape(geometry_)) {
    throw Error("light probe: image is " + std::to_string(probe.width()) + "x" + std::to_string(probe.height()) +
                " but the sampler was made for " + std::to_string(geometry_.width()) + "x" +
                std::to_string(geometry_.height()));
  }
  Resources& r = *resources_;
  const auto n = static_cast<std::uint32_t>(options.samples);
  const std::size_t sample_bytes = n * sizeof(gpu::ImportanceSampleOut);
  if (!r.samples || r.samples->size_bytes() < sample_bytes) {
    r.warp_set = {};
    r.samples.emplace(context_, sample_bytes);
    r.warp_set = r.warp_pipeline.bind({&r.pyramid, &r.radiance, &r.solid_angle, &*r.samples});
  }
  context_.transfer().upload(probe.bytes(), r.radiance);

  const auto width = static_cast<gpu::uint>(probe.width());
  const auto height = static_cast<gpu::uint>(probe.height());
  const auto levels = static_cast<gpu::uint>(r.levels);
  const auto [offset_u, offset_v] = seed_offsets(options.seed);
  const FisheyeCamera& fisheye = geometry_.calibration().fisheye;
  gpu::ImportanceWarpParams warp{};
  warp.samples = n;
  warp.levels = levels;
  warp.width = width;
  warp.height = height;
  warp.projection = geometry_.calibration().projection == ProbeProjection::Fisheye ? 0u : 1u;
  warp.inverse_samples = 1.f / static_cast<float>(n);
  warp.offset_u = offset_u;
  warp.offset_v = offset_v;
  warp.cx = static_cast<float>(fisheye.cx);
  warp.cy = static_cast<float>(fisheye.cy);
  warp.focal = static_cast<float>(fisheye.focal());
  warp.max_theta = static_cast<float>(fisheye.max_theta);
  for (int i = 0; i < 9; ++i) warp.probe_to_world[i] = static_cast<float>(geometry_.calibration().probe_to_world(i / 3, i % 3));

  context_.submit([&](VkCommandBuffer cmd) {
    r.timer.start(cmd);
    gpu::uint offset = 0, previous_offset = 0;
    for (gpu::uint level = 0; level <= levels; ++level) {
      const gpu::uint size = 1u << (levels - level);
      const gpu::ImportancePyramidParams params{width, height, size, level, previous_offset, offset};
      constexpr std::uint32_t local = RELIGHT_IMPORTANCE_PYRAMID_LOCAL_SIZE;
      if (level > 0) shader_write_to_read_barrier(cmd);
      r.pyramid_pipeline.dispatch(cmd, r.pyramid_set, params, vk::ComputePipeline::group_count(size, local),
                                  vk::ComputePipeline::group_count(size, local));
      previous_offset = offset;
      offset += size * size;
    }
    shader_write_to_read_barrier(cmd);
    r.warp_pipeline.dispatch(cmd, r.warp_set, warp,
                             vk::ComputePipeline::group_count(n, RELIGHT_IMPORTANCE_WARP_LOCAL_SIZE), 1);
    r.timer.stop(cmd);
  });
  last_gpu_ms_ = r.timer.elapsed_ms();

  std::vector<gpu::ImportanceSampleOut> out(n);
  context_.transfer().download(*r.samples, std::as_writable_bytes(std::span(out)));
  LightSet set;
  set.lights.reserve(n);
  if (samples_out) samples_out->clear();
  for (const auto& sample : out) {
    Light light;
    light.direction = Eigen::Vector3d(sample.direction[0], sample.direction[1], sample.direction[2]);
    light.power = Eigen::Vector3d(sample.power[0], sample.power[1], sample.power[2]);
    set.lights.push_back(light);
    if (samples_out) samples_out->push_back({sample.pixel, sample.u, sample.v});
  }
  return set;
}

}  // namespace relight::lights
