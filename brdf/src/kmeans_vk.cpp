// Vulkan K-means engine (kmeans_vk.h).
#include "relight/brdf/kmeans_vk.h"

#include <string>
#include <vector>

#include "relight/brdf/brdf_shared.h"
#include "relight/core/error.h"
#include "relight/shaders/brdf_kmeans_comp.h"
#include "relight/vk/barrier.h"
#include "relight/vk/buffer.h"
#include "relight/vk/compute_pipeline.h"
#include "relight/vk/context.h"
#include "relight/vk/timer.h"
#include "relight/vk/transfer.h"

namespace relight::brdf {

namespace {
constexpr std::uint32_t kGroup = RELIGHT_KMEANS_GROUP;
constexpr std::uint32_t kSums = RELIGHT_KMEANS_SUMS;
}  // namespace

struct KMeansVk::Resources {
  explicit Resources(vk::VulkanContext& context)
      : pipeline(context, {.spirv = shaders::brdf_kmeans_comp,
                           .storage_buffers = 4,
                           .push_constant_bytes = sizeof(gpu::KMeansParams),
                           .max_descriptor_sets = 2}),
        timer(context),
        centres(context, RELIGHT_KMEANS_MAX_CLUSTERS * 4 * sizeof(float), vk::BufferDomain::Upload) {}
  vk::ComputePipeline pipeline;
  vk::GpuTimer timer;
  // Host-visible, so that the centres of an iteration need no copy of their own.
  vk::VulkanBuffer centres;
  std::optional<vk::VulkanBuffer> points, labels, partials;
  std::optional<vk::VulkanBuffer> partials_host;  // read-back copy, filled in the iteration's own submission
  vk::UniqueDescriptorSet set;
  std::vector<std::uint32_t> rows;  // host copy of the partial sums
};

KMeansVk::KMeansVk(vk::VulkanContext& context)
    : context_(context), resources_(std::make_unique<Resources>(context)) {}

KMeansVk::~KMeansVk() = default;

void KMeansVk::set_points(std::span<const Float3> points) {
  if (points.size() / kGroup >= 65535) throw Error("brdf K-means (Vulkan): too many points for one dispatch");
  Resources& r = *resources_;
  const std::size_t bytes = points.size_bytes();
  const std::size_t groups = (points.size() + kGroup - 1) / kGroup;
  const std::size_t partial_bytes = groups * RELIGHT_KMEANS_MAX_CLUSTERS * kSums * sizeof(std::uint32_t);
  // The number of points changes every frame; a steady run should not allocate.
  bool grew = vk::reserve_with_headroom(r.points, context_, bytes);
  grew = vk::reserve_with_headroom(r.labels, context_, points.size() * sizeof(std::uint32_t)) || grew;
  grew = vk::reserve_with_headroom(r.partials, context_, partial_bytes) || grew;
  vk::reserve_with_headroom(r.partials_host, context_, partial_bytes, vk::BufferDomain::Readback);
  if (grew) {
    r.set = {};  // the old set refers to the old buffers
    r.set = r.pipeline.bind({&*r.points, &r.centres, &*r.labels, &*r.partials});
  }
  context_.transfer().upload(std::as_bytes(points), *r.points);
  points_ = loaded_ = static_cast<std::uint32_t>(points.size());
}

ClusterSums KMeansVk::step(std::span<const Eigen::Vector3f> centres) {
  const auto k_count = static_cast<std::uint32_t>(centres.size());
  if (k_count < 1 || k_count > RELIGHT_KMEANS_MAX_CLUSTERS) throw Error("brdf K-means (Vulkan): bad cluster count");
  Resources& r = *resources_;
  ClusterSums total;
  total.clusters.resize(k_count);
  if (points_ == 0) return total;
  std::vector<float> packed(static_cast<std::size_t>(k_count) * 4, 0.f);
  for (std::uint32_t k = 0; k < k_count; ++k) {
    for (int c = 0; c < 3; ++c) packed[4 * k + static_cast<std::uint32_t>(c)] = centres[k][c];
  }
  r.centres.write(std::as_bytes(std::span<const float>(packed)));
  const std::uint32_t groups = vk::ComputePipeline::group_count(points_, kGroup);
  const gpu::KMeansParams params{points_, k_count};
  const std::size_t slots = static_cast<std::size_t>(k_count) * kSums;
  r.rows.resize(groups * slots);
  const std::span<std::byte> rows = std::as_writable_bytes(std::span<std::uint32_t>(r.rows));
  // One submission per Lloyd iteration: on a discrete GPU the fence round trips, not the
  // dispatch, are the cost (three per iteration made the Vulkan engine no faster than the CPU).
  context_.submit([&](VkCommandBuffer cmd) {
    r.timer.start(cmd);
    r.pipeline.dispatch(cmd, r.set, params, groups, 1);
    r.timer.stop(cmd);
    vk::memory_barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT);
    const VkBufferCopy region{0, 0, rows.size()};
    vkCmdCopyBuffer(cmd, r.partials->handle(), r.partials_host->handle(), 1, &region);
    vk::memory_barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT);
  });
  if (const auto ms = r.timer.elapsed_ms()) gpu_ms_ = gpu_ms_.value_or(0.0) + *ms;
  r.partials_host->read(rows);
  for (std::uint32_t g = 0; g < groups; ++g) {
    const std::uint32_t* row = r.rows.data() + g * slots;
    for (std::uint32_t k = 0; k < k_count; ++k) {
      ClusterSums::Cluster& t = total.clusters[k];
      const std::uint32_t* s = row + k * kSums;
      t.sum[0] += s[0];
      t.sum[1] += s[1];
      t.sum[2] += s[2];
      t.count += s[3];
      t.distance += s[4];
    }
  }
  return total;
}

void KMeansVk::read_labels(std::vector<std::uint8_t>& labels) {
  std::vector<std::uint32_t> wide(points_);
  if (points_ > 0) {
    context_.transfer().download(*resources_->labels, std::as_writable_bytes(std::span<std::uint32_t>(wide)));
  }
  labels.assign(wide.begin(), wide.end());
}

}  // namespace relight::brdf
