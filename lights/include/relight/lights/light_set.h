#pragma once
// LightSet: the light sources that BRDF estimation and the renderer use, as a frame-graph buffer.
//
// Units. A directional light stands for the radiance arriving from a patch of the environment:
// `power` is the RGB irradiance it delivers to a surface facing it (W/m^2, i.e. radiance times
// solid angle), so the irradiance on a surface of normal n is sum_i power_i * max(0, n . d_i).
// A point light's `power` is its radiant intensity (W/sr per channel), as synth::PointLight; a
// spot light's is its radiant intensity on its axis, full within `inner_degrees` of the axis and
// fading smoothly (smoothstep of the cosine) to zero at `cone_degrees` (a real lamp's cone).
// Directions and positions are in the scene (world) frame; a direction points towards the light.
#include <Eigen/Core>
#include <vector>

namespace relight::lights {

enum class LightKind { Directional, Point, Spot };

struct Light {
  LightKind kind = LightKind::Directional;
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();  ///< unit, towards the light (directional)
  Eigen::Vector3d position = Eigen::Vector3d::Zero();    ///< metres (point and spot lights)
  Eigen::Vector3d power = Eigen::Vector3d::Zero();       ///< RGB, see the units above
  /// True for lights measured in the real scene (probe), false for lights of virtual objects:
  /// differential rendering treats the two differently.
  bool real = true;
  Eigen::Vector3d axis = -Eigen::Vector3d::UnitZ();  ///< unit, the direction a spot light shines along
  double cone_degrees = 30.0;                        ///< spot: half-angle where the light ends, (0, 90)
  double inner_degrees = 24.0;                       ///< spot: half-angle of full intensity, (0, cone]
};

struct LightSet {
  static constexpr const char* type_name = "LightSet";
  std::vector<Light> lights;
};

/// Rec. 709 luminance of a linear RGB value (the importance of a probe pixel).
[[nodiscard]] inline double luminance(const Eigen::Vector3d& rgb) {
  return 0.2126 * rgb.x() + 0.7152 * rgb.y() + 0.0722 * rgb.z();
}

/// Irradiance (RGB) the directional lights of `set` deliver to a surface of unit normal `normal`.
[[nodiscard]] Eigen::Vector3d irradiance(const LightSet& set, const Eigen::Vector3d& normal);

/// The spot falloff of `light` towards unit direction `from_light` (from the light to the point):
/// 1 within inner_degrees of the axis, 0 beyond cone_degrees, smoothstep of the cosine between;
/// 1 for other kinds.
[[nodiscard]] double spot_falloff(const Light& light, const Eigen::Vector3d& from_light);

/// Sum of the lights' RGB power.
[[nodiscard]] Eigen::Vector3d total_power(const LightSet& set);

/// The few strong lights hidden in a dense VPL set: greedily (strongest first) merges every
/// directional light within `radius` radians of a cluster's first light into it (power summed,
/// direction the power-weighted mean), strongest cluster first. Point lights pass unchanged.
[[nodiscard]] LightSet cluster_lights(const LightSet& set, double radius);

}  // namespace relight::lights
