#include "relight/lights/light_set.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace relight::lights {

Eigen::Vector3d irradiance(const LightSet& set, const Eigen::Vector3d& normal) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Light& light : set.lights) {
    if (light.kind == LightKind::Directional) sum += light.power * std::max(0.0, normal.dot(light.direction));
  }
  return sum;
}

double spot_falloff(const Light& light, const Eigen::Vector3d& from_light) {
  if (light.kind != LightKind::Spot) return 1.0;
  const double to_radians = std::numbers::pi / 180.0;
  const double cos_outer = std::cos(light.cone_degrees * to_radians);
  const double cos_inner = std::cos(light.inner_degrees * to_radians);
  const double c = light.axis.normalized().dot(from_light);
  if (c <= cos_outer) return 0.0;
  if (c >= cos_inner) return 1.0;
  const double x = (c - cos_outer) / (cos_inner - cos_outer);
  return x * x * (3.0 - 2.0 * x);
}

Eigen::Vector3d total_power(const LightSet& set) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Light& light : set.lights) sum += light.power;
  return sum;
}

LightSet cluster_lights(const LightSet& set, double radius) {
  std::vector<Light> directional;
  LightSet clustered;
  for (const Light& light : set.lights) {
    (light.kind == LightKind::Directional ? directional : clustered.lights).push_back(light);
  }
  std::stable_sort(directional.begin(), directional.end(),
                   [](const Light& a, const Light& b) { return luminance(a.power) > luminance(b.power); });
  const double cos_radius = std::cos(radius);
  std::vector<bool> taken(directional.size(), false);
  std::vector<Light> clusters;
  for (std::size_t seed = 0; seed < directional.size(); ++seed) {
    if (taken[seed]) continue;
    Light cluster = directional[seed];
    Eigen::Vector3d weighted = Eigen::Vector3d::Zero();
    cluster.power.setZero();
    for (std::size_t other = seed; other < directional.size(); ++other) {
      if (taken[other] || directional[seed].direction.dot(directional[other].direction) < cos_radius) continue;
      taken[other] = true;
      cluster.power += directional[other].power;
      weighted += luminance(directional[other].power) * directional[other].direction;
    }
    if (weighted.norm() > 0.0) cluster.direction = weighted.normalized();
    clusters.push_back(cluster);
  }
  std::stable_sort(clusters.begin(), clusters.end(),
                   [](const Light& a, const Light& b) { return luminance(a.power) > luminance(b.power); });
  clustered.lights.insert(clustered.lights.begin(), clusters.begin(), clusters.end());
  return clustered;
}

}  // namespace relight::lights
