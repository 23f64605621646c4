#pragma once
// The Vulkan K-means engine (kmeans.h): one compute dispatch per Lloyd iteration
// (shaders/brdf_kmeans.comp) does the assignment and the per-cluster reduction (colour sum,
// count, squared-distance sum) per work group of 256 points; the host adds the groups' rows
// (1200 rows of 5 uints per cluster for 640x480) and updates the centres. The sums are exact
// integers, so for the same initial centres this engine and KMeansCpu give identical sums,
// centres and assignments (tested). This header includes no Vulkan headers.
#include <algorithm>
#include <memory>
#include <optional>

#include "relight/brdf/kmeans.h"

namespace relight::vk {
class VulkanContext;
}  // namespace relight::vk

namespace relight::brdf {

class KMeansVk final : public KMeansEngine {
 public:
  explicit KMeansVk(vk::VulkanContext& context);
  ~KMeansVk() override;
  KMeansVk(const KMeansVk&) = delete;
  KMeansVk& operator=(const KMeansVk&) = delete;

  void set_points(std::span<const Float3> points) override;
  void use_first(std::size_t count) override {
    points_ = static_cast<std::uint32_t>(std::min<std::size_t>(count, loaded_));
  }
  ClusterSums step(std::span<const Eigen::Vector3f> centres) override;
  void read_labels(std::vector<std::uint8_t>& labels) override;

  /// GPU time of the dispatches since the last reset_gpu_ms() (timestamp queries), if known.
  [[nodiscard]] std::optional<double> gpu_ms() const { return gpu_ms_; }
  void reset_gpu_ms() { gpu_ms_.reset(); }

 private:
  struct Resources;
  vk::VulkanContext& context_;
  std::unique_ptr<Resources> resources_;
  std::uint32_t points_ = 0;  // points that step() works on
  std::uint32_t loaded_ = 0;  // points of the last set_points()
  std::optional<double> gpu_ms_;
};

}  // namespace relight::brdf
