#pragma once
// The first ray of a light path aimed at the specular objects, for the two caustic techniques:
// the path tracer's light tracing (reference/caustic_light_tracer.h) and DIR's caustic photons
// (dir/caustic_photons.h). Directions from a point or spot light are uniform in the cone around
// the sphere `target` (every direction that can hit it lies inside; the whole sphere of
// directions when the light is inside it); a directional light's rays cross a disc of the
// sphere's radius across its direction, started outside the whole scene (`scene`).
#include <optional>

#include "relight/render/scene/mr_scene.h"

namespace relight::render::detail {

/// A light path's first ray and its flux weight (flux / pdf).
struct Emission {
  Eigen::Vector3f origin;
  Eigen::Vector3f direction;
  Eigen::Vector3f beta;
};

/// A direction from `origin` uniform in the cone around the sphere `target` (the whole sphere of
/// directions when `origin` lies inside it) and its density (per steradian).
struct ConeSample {
  Eigen::Vector3f direction;
  float pdf = 0.f;
};
[[nodiscard]] ConeSample sample_cone_towards(const Eigen::Vector3f& origin, const BoundingSphere& target, float u1,
                                             float u2);

/// Samples the first ray from `light` towards `target` with the uniform numbers u1, u2; none
/// where a spot light's cone gives it no light.
[[nodiscard]] std::optional<Emission> emit_towards(const MrLight& light, const BoundingSphere& target,
                                                   const BoundingSphere& scene, float u1, float u2);

}  // namespace relight::render::detail
