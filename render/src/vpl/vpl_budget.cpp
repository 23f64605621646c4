#include "vpl/vpl_budget.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <utility>

#include "vpl/light_sampling.h"

namespace relight::render::vpl_detail {

double power_weight(const MrLight& light, const BoundingSphere& bounds) {
  // Power: intensity times solid angle, or for a directional light irradiance times the area of
  // the scene's cross-section.
  const float extent = light.kind == LightKind::Directional ? kPi * std::max(bounds.radius, 0.f) * std::max(bounds.radius, 0.f)
                                                            : emission_solid_angle(light);
  return std::max(0.f, luminance(light.intensity)) * extent;
}

/// The weights of VplBudget (vpl.h) for the lights that emit VPLs; 0 for the others.
std::vector<double> budget_weights(const MrScene& scene, const BoundingSphere& bounds, const VplOptions& options) {
  const std::size_t n = scene.lights.size();
  // The first frame of ByPreviousFlux (no flux yet) shares equally, the paper's default mode.
  const VplBudget budget =
      options.budget == VplBudget::ByPreviousFlux && options.previous_flux.empty() ? VplBudget::Equal : options.budget;
  std::vector<double> weight(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    const MrLight& light = scene.lights[i];
    if (!emits_vpls(light)) continue;
    switch (budget) {
      case VplBudget::Equal: weight[i] = 1.0; break;
      case VplBudget::ByPower:
      case VplBudget::ByPreviousFlux: weight[i] = power_weight(light, bounds); break;
      case VplBudget::ByWeight: weight[i] = i < options.light_weights.size() ? options.light_weights[i] : 1.0; break;
    }
  }
  if (budget != VplBudget::ByPreviousFlux) return weight;
  // Lights without last frame's flux keep their power weight, scaled by the ratio of flux to
  // power of the lights that have one.
  double flux_sum = 0.0, power_sum = 0.0;
  for (std::size_t i = 0; i < n && i < options.previous_flux.size(); ++i) {
    if (weight[i] <= 0.0) continue;
    flux_sum += std::max(0.0, options.previous_flux[i]);
    power_sum += weight[i];
  }
  if (flux_sum <= 0.0) return weight;  // nothing reached a surface last frame: by power
  const double scale = flux_sum / power_sum;
  double mean = 0.0, emitting = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (weight[i] <= 0.0) continue;
    weight[i] = i < options.previous_flux.size() ? std::max(0.0, options.previous_flux[i]) : weight[i] * scale;
    mean += weight[i];
    emitting += 1.0;
  }
  mean /= emitting;
  for (std::size_t i = 0; i < n; ++i) {
    if (emits_vpls(scene.lights[i])) weight[i] = std::max(weight[i], mean / 16.0);
  }
  return weight;
}

/// Light samples per light, by the weights of the budget.
std::vector<int> light_budget(const MrScene& scene, const BoundingSphere& bounds, const VplOptions& options) {
  const std::vector<double> weight = budget_weights(scene, bounds, options);
  double total = 0.0;
  for (double w : weight) total += std::max(0.0, w);
  std::vector<int> count(scene.lights.size(), 0);
  if (total <= 0.0) return count;
  // Largest remainder, so that the shares add up to options.count exactly.
  int given = 0;
  std::vector<std::pair<double, std::size_t>> remainder;
  for (std::size_t i = 0; i < weight.size(); ++i) {
    const double exact = options.count * std::max(0.0, weight[i]) / total;
    count[i] = static_cast<int>(std::floor(exact));
    given += count[i];
    remainder.emplace_back(exact - count[i], i);
  }
  std::sort(remainder.begin(), remainder.end(), std::greater<>());
  for (int i = 0; i < options.count - given; ++i) ++count[remainder[static_cast<std::size_t>(i) % remainder.size()].second];
  return count;
}

}  // namespace relight::render::vpl_detail
