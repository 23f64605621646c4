#pragma once
// The VPL budget (VplBudget of vpl.h): how many light samples each light gets this frame.
#include <vector>

#include "relight/render/scene/mr_scene.h"
#include "relight/render/vpl/vpl.h"

namespace relight::render::vpl_detail {

/// A light's power: intensity times solid angle, or for a directional light irradiance times
/// the area of the scene's cross-section.
[[nodiscard]] double power_weight(const MrLight& light, const BoundingSphere& bounds);
/// The weights of VplBudget for the lights that emit VPLs; 0 for the others.
[[nodiscard]] std::vector<double> budget_weights(const MrScene& scene, const BoundingSphere& bounds,
                                                 const VplOptions& options);
/// Light samples per light, by the weights of the budget (largest remainder: they add up to
/// options.count exactly).
[[nodiscard]] std::vector<int> light_budget(const MrScene& scene, const BoundingSphere& bounds, const VplOptions& options);

}  // namespace relight::render::vpl_detail
