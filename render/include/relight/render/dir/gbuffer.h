#pragma once
// The G-buffer of one view (Knecht's dissertation §5.2.2): per pixel the nearest surface of the
// whole mixed-reality scene through the pixel centre, with the real/virtual flag r(p).
//
// gbuffer_cpu() casts one ray per pixel with Embree; it is the reference for the rasterised
// G-buffer (gbuffer_vk.h), which stores r(p) in the sign of the distance as the paper does.
#include "relight/core/image.h"
#include "relight/render/scene/mr_scene.h"
#include "relight/render/reference/ray_tracer.h"

namespace relight::render {

struct GBuffer {
  PositionMap position;  ///< world frame, metres; (0,0,0) where nothing is seen
  NormalMap normal;      ///< world frame, unit, facing the camera (interpolated vertex normal, before any normal map)
  LabelImage material;   ///< MrScene material index + 1; 0 where nothing is seen
  Mask virtual_surface;  ///< 1 where the surface belongs to a virtual object (r(p) = 0)
  DepthMap distance;     ///< from the camera centre, metres; 0 where nothing is seen
  /// (u, v, footprint) where the surface has texture coordinates, zero elsewhere: its texture
  /// coordinates and the pixel's footprint in them, the longer of how far (u, v) moves to the
  /// next pixel right and below (Texture::level_of_detail); empty when no material of the scene
  /// has a texture.
  Image<Float3> texcoord{};
  /// The tangent frame where the surface has texture coordinates (encode_tangent(), normal_map.h:
  /// for the normal as stored, facing the camera), 0 elsewhere; empty with texcoord.
  Image<float> tangent{};

  static constexpr const char* type_name = "GBuffer";
};

/// Whether any material of `scene` has a texture (then G-buffers carry texcoord).
[[nodiscard]] bool has_textures(const MrScene& scene);

enum class MaterialTexture { BaseColor, Emission, MetallicRoughness, Normal };
/// The factor a material texture gives k_d (BaseColor) or the emission, or the metallic-
/// roughness texel surface_phong() reads (MetallicRoughness), or the normal texture's texel
/// (Normal), at each pixel of
/// `gbuffer` (Texture::sample at the pixel's coordinates and footprint; the texture's mean on a
/// textured material without coordinates there); 1 elsewhere. Empty when `gbuffer` carries no
/// texture coordinates or no material has such a texture.
[[nodiscard]] RadianceImage texture_factors(const GBuffer& gbuffer, const MrScene& scene, MaterialTexture which);
/// texture_factors()' factor at pixel (x, y): 1 where it is empty.
[[nodiscard]] inline Eigen::Vector3f texture_factor_at(const RadianceImage& factors, int x, int y) {
  if (factors.empty()) return Eigen::Vector3f::Ones();
  const Float3& f = factors(y, x);
  return {f.x, f.y, f.z};
}

/// The shading normal at each pixel of `gbuffer`: its normal bent by its material's normal
/// texture (normal_map.h; at the pixel's footprint, in its tangent frame), the normal itself
/// where the material has none or the pixel no frame. Empty when no material has a normal
/// texture or `gbuffer` no texture coordinates.
[[nodiscard]] NormalMap shading_normals(const GBuffer& gbuffer, const MrScene& scene);

/// A G-buffer of `width` x `height` that sees nothing, with texture coordinates and tangents when
/// `textured`.
[[nodiscard]] GBuffer empty_gbuffer(int width, int height, bool textured);

/// Stores at (row, col) the surface `hit` seen along `direction` (unit): its normal turned to
/// face the ray, and where it has texture coordinates (and `g` has room for them) those and its
/// frame with the footprint `texcoord_footprint`.
void store_hit(GBuffer& g, int row, int col, const SurfaceHit& hit, const Eigen::Vector3f& direction,
               float texcoord_footprint);

[[nodiscard]] GBuffer gbuffer_cpu(const RayTracer& tracer, const MrCamera& camera, int threads = 0);

}  // namespace relight::render
