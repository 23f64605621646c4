#pragma once
// Quality measures of normal and depth maps against ground truth, shared by the tests and the
// benchmarks so that both report the same numbers.
#include <cstddef>

#include "relight/core/image.h"

namespace relight::reconstruct {

struct AngularError {
  double mean_deg = 0.0;      ///< mean angle between estimate and truth over `compared` pixels
  double median_deg = 0.0;
  std::size_t compared = 0;   ///< pixels where both (and the region mask, if any) are valid
  double coverage = 0.0;      ///< compared / pixels with a true normal (inside the region)
};

/// Angle acos(clamp(n̂·n)) in degrees per pixel with both normals valid (and region != 0).
[[nodiscard]] AngularError angular_error(const NormalMap& estimate, const NormalMap& truth,
                                         const Mask* region = nullptr);

/// Pixels whose true normal agrees within `max_angle_deg` with every true normal in the
/// (2 radius + 1)² window around it: the flat regions of the scene.
[[nodiscard]] Mask flat_region_mask(const NormalMap& truth, int radius = 3, double max_angle_deg = 1.0);

/// Pixels whose true depth is valid and within `max_step_rel` · z of every valid-or-missing
/// neighbour in the (2 radius + 1)² window: surfaces away from depth discontinuities, where
/// lateral sensor noise swaps foreground and background and no temporal filter can help.
[[nodiscard]] Mask continuous_depth_mask(const DepthMap& truth, int radius = 2, double max_step_rel = 0.02);

struct DepthError {
  double rmse_m = 0.0;
  std::size_t compared = 0;  ///< pixels valid in both (and in the region, if any)
};
[[nodiscard]] DepthError depth_rmse(const DepthMap& estimate, const DepthMap& truth, const Mask* region = nullptr);

}  // namespace relight::reconstruct
