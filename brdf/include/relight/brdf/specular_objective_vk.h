#pragma once
// The specular objective F of specular_fit.h (eq. 4.15) on the GPU, for a batch of parameter
// candidates at once: the per-pixel part of the fit (the model of shading.h at every sample,
// its squared residual and the sum) is a compute dispatch over samples x candidates
// (shaders/brdf_specular_objective.comp), one submission per batch. The model is evaluated in
// float (the CPU objective, specular_objective(), in double); tests hold the two to 1e-3
// relative.
//
// Reads: a SpecularProblem (samples, k_d, lights) and candidates (k_s, n, offsets of the
// SpecularOptions::moving_lights strongest lights, as in specular_objective()). Writes: F per
// candidate. SpecularFitStage on the Vulkan backend uses it to pick each cluster's starting
// point from a dense (k_s, n) grid. This header includes no Vulkan headers.
#include <Eigen/Core>
#include <array>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "relight/brdf/specular_fit.h"

namespace relight::vk {
class VulkanContext;
}  // namespace relight::vk

namespace relight::brdf {

struct SpecularCandidate {
  float ks = 0.f;
  float n = 1.f;
  /// Offsets of the moving lights (strongest first, moving_light_indices()); unused ones ignored.
  std::array<Eigen::Vector3f, 2> offsets{Eigen::Vector3f::Zero(), Eigen::Vector3f::Zero()};
};

class SpecularObjectiveVk {
 public:
  explicit SpecularObjectiveVk(vk::VulkanContext& context);
  ~SpecularObjectiveVk();
  SpecularObjectiveVk(const SpecularObjectiveVk&) = delete;
  SpecularObjectiveVk& operator=(const SpecularObjectiveVk&) = delete;

  /// F of `problem` at every candidate; the first min(options.moving_lights, 2) strongest lights
  /// move by the candidates' offsets.
  [[nodiscard]] std::vector<double> evaluate(const SpecularProblem& problem, const SpecularOptions& options,
                                             std::span<const SpecularCandidate> candidates);

  /// GPU time of the dispatches since the last reset_gpu_ms() (timestamp queries), if known.
  [[nodiscard]] std::optional<double> gpu_ms() const { return gpu_ms_; }
  void reset_gpu_ms() { gpu_ms_.reset(); }

 private:
  struct Resources;
  vk::VulkanContext& context_;
  std::unique_ptr<Resources> resources_;
  std::optional<double> gpu_ms_;
};

/// A grid of candidates with the lights fixed: `exponents` values of n spaced evenly in log n over
/// [options.n_min, options.n_max] times `strengths` values of k_s spaced evenly over
/// [0, options.ks_max], n-major.
[[nodiscard]] std::vector<SpecularCandidate> specular_start_grid(const SpecularOptions& options, int exponents,
                                                                 int strengths);

/// The candidate of specular_start_grid(options, exponents, strengths) with the lowest F on the
/// GPU, as the fits' starting point.
[[nodiscard]] SpecularStart best_grid_start(SpecularObjectiveVk& objective, const SpecularProblem& problem,
                                            const SpecularOptions& options, int exponents = 24, int strengths = 16);

}  // namespace relight::brdf
