#pragma once
// Triangle meshes of simple shapes: spheres, boxes, rectangles and z-axis cylinders, for the
// procedural models and for scenes built from analytic shapes (the synthetic scene's exact
// geometry in truth/scene_from_synth.h, the tests' rooms).
//
// Spheres and cylinders get interpolated vertex normals; boxes and rectangles are exact.
// `segments` sets the tessellation around a sphere's equator or a cylinder; 96 keeps the
// sphere's silhouette within 0.05 % of its radius. Every triangle gets `material`.
#include <Eigen/Core>
#include <cstdint>

#include "relight/render/scene/mr_scene.h"

namespace relight::render {

struct TessellationOptions {
  int segments = 96;  ///< at least 3, else relight::Error
};

[[nodiscard]] TriangleMesh tessellate_sphere(const Eigen::Vector3f& centre, float radius, std::uint32_t material,
                                             const TessellationOptions& options = {});
/// The axis-aligned box [lo, hi], normals outwards.
[[nodiscard]] TriangleMesh tessellate_box(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi, std::uint32_t material);
/// The rectangle centre ± half_u ± half_v facing `normal` (half_u, half_v orthogonal).
[[nodiscard]] TriangleMesh tessellate_rectangle(const Eigen::Vector3f& centre, const Eigen::Vector3f& normal,
                                                const Eigen::Vector3f& half_u, const Eigen::Vector3f& half_v,
                                                std::uint32_t material);
/// The closed cylinder standing on `base` along +z.
[[nodiscard]] TriangleMesh tessellate_z_cylinder(const Eigen::Vector3f& base, float radius, float height,
                                                 std::uint32_t material, const TessellationOptions& options = {});

}  // namespace relight::render
