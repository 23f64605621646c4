#pragma once
// Ray queries against an MrScene with Embree 3, split into two acceleration structures: one of
// the real meshes and one of the virtual meshes. Differential rendering needs every ray answered
// both with and without the virtual objects; two scenes answer that with one query each (the
// nearest hit of the whole scene is the nearer of the two), so no ray is traced twice.
#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>

#include "relight/render/scene/mr_scene.h"

namespace relight::render {

enum class Layer { Real, Virtual };

struct SurfaceHit {
  float t = 0.f;
  Eigen::Vector3f point;
  Eigen::Vector3f geometric_normal;  ///< unit, as the triangle's winding gives it
  Eigen::Vector3f interpolated_normal;  ///< unit, interpolated vertex normal (or the geometric one)
  /// unit: interpolated_normal bent by the material's normal texture (normal_map.h, level 0, in
  /// the triangle's tangent frame), where it has one and the hit texture coordinates
  Eigen::Vector3f shading_normal;
  std::uint32_t material = 0;
  bool real = true;
  /// Interpolated texture coordinates, and how they change with the point on the triangle's plane
  /// (d uv / d point, for a pixel's footprint); zero on meshes without texture coordinates.
  bool has_texcoord = false;  ///< false: the material's texture is taken at its mean colour
  Eigen::Vector2f texcoord = Eigen::Vector2f::Zero();
  Eigen::Matrix<float, 2, 3> texcoord_gradient = Eigen::Matrix<float, 2, 3>::Zero();
};

/// The factor k_d takes at a hit from its material's base-colour texture (at the hit's
/// coordinates, mip level `lod`; the texture's mean where the hit has none); 1 untextured.
[[nodiscard]] Eigen::Vector3f base_color_at(const MrScene& scene, const SurfaceHit& hit, float lod = 0.f);
/// The radiance a hit's material emits there (its emission times its emission texture).
[[nodiscard]] Eigen::Vector3f emission_at(const MrScene& scene, const SurfaceHit& hit);
/// Its material's metallic-roughness texture at a hit (texture_at(); 1 without one).
[[nodiscard]] Eigen::Vector3f metallic_roughness_at(const MrScene& scene, const SurfaceHit& hit, float lod = 0.f);
/// The Phong parameters at a hit: surface_phong() with metallic_roughness_at(), k_d times
/// base_color_at().
[[nodiscard]] Phong phong_at(const MrScene& scene, const SurfaceHit& hit, float lod = 0.f);

class RayTracer {
 public:
  /// Builds both acceleration structures over its own copy of `scene` (a temporary is moved in,
  /// not copied).
  /// Throws relight::Error when the scene is invalid or Embree cannot start.
  /// High: the slowest build and the fastest rays (Embree's spatial splits), for renderers
  /// that trace millions of rays; Fast: a quick build for a scene that changes every frame and
  /// sees few rays (the DIR stage's VPL generation on the reconstruction).
  enum class Build { High, Fast };
  explicit RayTracer(MrScene scene, Build build = Build::High);
  ~RayTracer();
  RayTracer(const RayTracer&) = delete;
  RayTracer& operator=(const RayTracer&) = delete;

  /// Nearest hit of `layer` along origin + t direction with t in (0, t_max); direction unit.
  [[nodiscard]] std::optional<SurfaceHit> intersect(Layer layer, const Eigen::Vector3f& origin,
                                                    const Eigen::Vector3f& direction,
                                                    float t_max = std::numeric_limits<float>::infinity()) const;
  /// Whether anything of `layer` lies along the ray with t in (0, t_max).
  [[nodiscard]] bool occluded(Layer layer, const Eigen::Vector3f& origin, const Eigen::Vector3f& direction,
                              float t_max) const;

  [[nodiscard]] bool has_virtual_geometry() const;
  /// The tracer's own copy of the scene (hits index its meshes and materials).
  [[nodiscard]] const MrScene& scene() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace relight::render
