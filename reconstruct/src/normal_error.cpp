#include "relight/reconstruct/normal_error.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace relight::reconstruct {

AngularError angular_error(const NormalMap& estimate, const NormalMap& truth, const Mask* region) {
  AngularError error;
  if (!estimate.same_shape(truth)) return error;
  std::vector<double> angles;
  std::size_t truth_count = 0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    if (region && region->pixels()[i] == 0) continue;
    const Float3& t = truth.pixels()[i];
    if (!is_valid_normal(t)) continue;
    ++truth_count;
    const Float3& e = estimate.pixels()[i];
    if (!is_valid_normal(e)) continue;
    const double cosine = dot(e, t) / (static_cast<double>(length(e)) * length(t));
    angles.push_back(std::acos(std::clamp(cosine, -1.0, 1.0)) * 180.0 / std::numbers::pi);
  }
  error.compared = angles.size();
  if (angles.empty()) return error;
  double sum = 0.0;
  for (double a : angles) sum += a;
  error.mean_deg = sum / static_cast<double>(angles.size());
  std::nth_element(angles.begin(), angles.begin() + static_cast<std::ptrdiff_t>(angles.size() / 2), angles.end());
  error.median_deg = angles[angles.size() / 2];
  error.coverage = static_cast<double>(angles.size()) / static_cast<double>(truth_count);
  return error;
}

Mask flat_region_mask(const NormalMap& truth, int radius, double max_angle_deg) {
  Mask mask(truth.width(), truth.height());
  const double min_cosine = std::cos(max_angle_deg * std::numbers::pi / 180.0);
  for (int r = 0; r < truth.height(); ++r) {
    for (int c = 0; c < truth.width(); ++c) {
      const Float3& centre = truth(r, c);
      if (!is_valid_normal(centre)) continue;
      bool flat = true;
      for (int dr = -radius; dr <= radius && flat; ++dr) {
        for (int dc = -radius; dc <= radius && flat; ++dc) {
          flat = truth.in_bounds(r + dr, c + dc) && dot(truth(r + dr, c + dc), centre) >= min_cosine;
        }
      }
      mask(r, c) = flat ? 1 : 0;
    }
  }
  return mask;
}

Mask continuous_depth_mask(const DepthMap& truth, int radius, double max_step_rel) {
  Mask mask(truth.width(), truth.height());
  for (int r = 0; r < truth.height(); ++r) {
    for (int c = 0; c < truth.width(); ++c) {
      const float z = truth(r, c);
      if (!is_valid_depth(z)) continue;
      bool continuous = true;
      for (int dr = -radius; dr <= radius && continuous; ++dr) {
        for (int dc = -radius; dc <= radius && continuous; ++dc) {
          continuous = !truth.in_bounds(r + dr, c + dc) ||
                       (is_valid_depth(truth(r + dr, c + dc)) && std::fabs(truth(r + dr, c + dc) - z) <= max_step_rel * z);
        }
      }
      mask(r, c) = continuous ? 1 : 0;
    }
  }
  return mask;
}

DepthError depth_rmse(const DepthMap& estimate, const DepthMap& truth, const Mask* region) {
  DepthError error;
  if (!estimate.same_shape(truth)) return error;
  double sum = 0.0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    if (region && region->pixels()[i] == 0) continue;
    const float e = estimate.pixels()[i];
    const float t = truth.pixels()[i];
    if (!is_valid_depth(e) || !is_valid_depth(t)) continue;
    sum += (static_cast<double>(e) - t) * (static_cast<double>(e) - t);
    ++error.compared;
  }
  if (error.compared > 0) error.rmse_m = std::sqrt(sum / static_cast<double>(error.compared));
  return error;
}

}  // namespace relight::reconstruct
