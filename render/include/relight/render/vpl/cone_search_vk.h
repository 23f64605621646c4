#pragma once
// The point-cone search (definition and CPU reference in cone_search.h) on Vulkan: one work group
// of shaders/cone_search.comp per query scans the points and reduces to the winner. The same
// winners as the CPU except where two candidates' depths differ by the device's rounding.
//
// Reads:  points (packed RELIGHT_CONE_POINT_FLOATS floats each), queries (packed
//         RELIGHT_CONE_QUERY_FLOATS floats each; cone_search_shared.h).
// Writes: hits (2 words per query: t's float bits, point index or RELIGHT_CONE_NO_POINT).
// This header includes no Vulkan headers.
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "relight/render/vpl/cone_search.h"

namespace relight::vk {
class VulkanContext;
}  // namespace relight::vk

namespace relight::render {

/// Holds the pipeline, and the point buffer between searches over the same points.
class ConeSearchVk {
 public:
  explicit ConeSearchVk(vk::VulkanContext& context);
  ~ConeSearchVk();
  ConeSearchVk(const ConeSearchVk&) = delete;
  ConeSearchVk& operator=(const ConeSearchVk&) = delete;

  /// Uploads the candidate points (kept for the following searches).
  void set_points(std::span<const IsmPoint> points);
  /// cone_search_cpu on the device for the points of the last set_points(). Waits for the
  /// result. Throws relight::Error on a half-angle outside (0, 90) degrees.
  [[nodiscard]] std::vector<ConeHit> search(std::span<const ConeQuery> queries, float half_angle_deg);
  /// GPU milliseconds of the last search, when the device has timestamps.
  [[nodiscard]] std::optional<double> last_gpu_ms() const;
  /// The GPU milliseconds of every search since the last call (0 without timestamps): what a
  /// stage that searches several times per frame reports.
  double take_gpu_ms();

 private:
  struct State;
  vk::VulkanContext& context_;
  std::unique_ptr<State> state_;
};

}  // namespace relight::render
