#include "relight/vk/timer.h"

#include "relight/vk/check.h"
#include "relight/vk/context.h"

namespace relight::vk {

GpuTimer::GpuTimer(const VulkanContext& context) {
  if (!context.timestamps_supported()) return;
  period_ns_ = context.timestamp_period_ns();
  const std::uint32_t bits = context.timestamp_valid_bits();
  mask_ = bits >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << bits) - 1;
  VkQueryPoolCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO;
  info.queryType = VK_QUERY_TYPE_TIMESTAMP;
  info.queryCount = 2;
  VkQueryPool pool = VK_NULL_HANDLE;
  RELIGHT_VK_CHECK(vkCreateQueryPool(context.device(), &info, nullptr, &pool));
  pool_ = UniqueQueryPool(context.device(), pool);
}

void GpuTimer::start(VkCommandBuffer cmd) {
  if (!pool_) return;
  vkCmdResetQueryPool(cmd, pool_.get(), 0, 2);
  vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, pool_.get(), 0);
  started_ = true;
  stopped_ = false;
}

void GpuTimer::stop(VkCommandBuffer cmd) {
  if (!pool_ || !started_) return;
  vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, pool_.get(), 1);
  stopped_ = true;
}

std::optional<double> GpuTimer::elapsed_ms() const {
  if (!pool_ || !started_ || !stopped_) return std::nullopt;
  std::uint64_t ticks[2] = {0, 0};
  // No WAIT flag: asking before the submission finished must not hang; it reports "not ready".
  const VkResult result = vkGetQueryPoolResults(pool_.device(), pool_.get(), 0, 2, sizeof(ticks), ticks,
                                                sizeof(std::uint64_t), VK_QUERY_RESULT_64_BIT);
  if (result == VK_NOT_READY) return std::nullopt;
  RELIGHT_VK_CHECK(result);
  const std::uint64_t elapsed = (ticks[1] - ticks[0]) & mask_;
  return static_cast<double>(elapsed) * period_ns_ * 1e-6;
}

}  // namespace relight::vk
