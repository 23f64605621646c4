#include "relight/lights/merge_lights.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numbers>
#include <vector>

namespace relight::lights {

namespace {

/// A directional light being merged: its power and the power-weighted sum of its directions.
struct Cluster {
  Eigen::Vector3d power = Eigen::Vector3d::Zero();
  Eigen::Vector3d weighted_direction = Eigen::Vector3d::Zero();
  [[nodiscard]] Eigen::Vector3d direction() const {
    const double norm = weighted_direction.norm();
    return norm > 0.0 ? Eigen::Vector3d(weighted_direction / norm) : Eigen::Vector3d::UnitZ();
  }
};

/// Merges the closest pair of `clusters` until at most `max_count` are left and no two are closer
/// than `min_cos` (O(n^3); n is a probe's light count, at most a few hundred).
void merge_down(std::vector<Cluster>& clusters, std::size_t max_count, double min_cos = 2.0) {
  while (clusters.size() > 1) {
    std::size_t best_a = 0, best_b = 1;
    double best_cos = -std::numeric_limits<double>::infinity();
    for (std::size_t a = 0; a < clusters.size(); ++a)
      for (std::size_t b = a + 1; b < clusters.size(); ++b) {
        const double cos_ab = clusters[a].direction().dot(clusters[b].direction());
        if (cos_ab > best_cos) {
          best_cos = cos_ab;
          best_a = a;
          best_b = b;
        }
      }
    if (clusters.size() <= max_count && best_cos < min_cos) break;
    clusters[best_a].power += clusters[best_b].power;
    clusters[best_a].weighted_direction += clusters[best_b].weighted_direction;
    clusters.erase(clusters.begin() + static_cast<std::ptrdiff_t>(best_b));
  }
}

/// The set with its real and its virtual directional lights each merged by `merge` (point and
/// spot lights first, unchanged).
template <class Merge>
LightSet merged(const LightSet& set, const Merge& merge) {
  LightSet out;
  std::vector<Cluster> real, virtual_lights;
  for (const Light& light : set.lights) {
    if (light.kind != LightKind::Directional) {
      out.lights.push_back(light);
      continue;
    }
    // A light without luminance still keeps its direction in the merge.
    const double weight = std::max(luminance(light.power), 1e-12);
    (light.real ? real : virtual_lights).push_back({light.power, weight * light.direction.normalized()});
  }
  for (auto* clusters : {&real, &virtual_lights}) {
    merge(*clusters);
    for (const Cluster& cluster : *clusters) {
      Light light;
      light.kind = LightKind::Directional;
      light.direction = cluster.direction();
      light.power = cluster.power;
      light.real = clusters == &real;
      out.lights.push_back(light);
    }
  }
  return out;
}

}  // namespace

LightSet merge_directional_lights(const LightSet& set, std::size_t max_directional) {
  std::size_t real_count = 0, virtual_count = 0;
  for (const Light& light : set.lights)
    if (light.kind == LightKind::Directional) ++(light.real ? real_count : virtual_count);
  if (real_count <= max_directional && virtual_count <= max_directional) return set;
  return merged(set, [max_directional](std::vector<Cluster>& clusters) { merge_down(clusters, max_directional); });
}

LightSet merge_close_directional_lights(const LightSet& set, double max_angle_degrees) {
  if (!(max_angle_degrees > 0.0)) return set;
  const double min_cos = std::cos(max_angle_degrees * std::numbers::pi / 180.0);
  return merged(set, [min_cos](std::vector<Cluster>& clusters) {
    merge_down(clusters, std::numeric_limits<std::size_t>::max(), min_cos);
  });
}

}  // namespace relight::lights
