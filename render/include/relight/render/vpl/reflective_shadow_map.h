#pragma once
// Reflective shadow maps (Dachsbacher & Stamminger, I3D 2005) of a spot light, as differential
// instant radiosity uses them (Knecht et al. 2010; dissertation §5.2.3): a virtual spot light
// sees the nearest surface of both layers in one RSM; a real spot light renders two, one through
// the real layer and one through the virtual layer, and the VPL slots are shared between them by
// the texels each covers.
//
// The view: a square perspective frustum along the spot's axis that just holds its outer cone,
// `size` x `size` texels. reflective_shadow_maps_cpu is the ray-cast reference; the rasterised
// RSMs of reflective_shadow_map_vk.h use the same view (RsmView) and the same per-texel rules
// (assemble_reflective_shadow_maps) on the nearest surfaces a G-buffer pass finds. A texel where
// the cone sees a surface stores
//   hit       the surface (point, normals, material, real/virtual);
//   flux      the flux I(omega) falloff(omega) dOmega that reaches it through the texel's solid
//             angle dOmega: what a first-bounce VPL there carries (vpl.h);
//   importance   luminance(flux) x max(luminance(k_d), kMinAlbedo): the diffusely reflected flux
//             that RSM sampling is proportional to, floored so that a dark or purely glossy
//             surface is still sampled (its VPLs stay unbiased, just noisier).
// In a real light's real RSM, `occluded_by_virtual` marks texels whose surface lies behind a
// virtual one (the real-only VPLs of Fig. 5.7); in its virtual RSM, texels behind a real surface
// are empty (no world sees them).
#include <Eigen/Core>
#include <functional>
#include <optional>
#include <vector>

#include "relight/render/scene/mr_scene.h"
#include "relight/render/reference/ray_tracer.h"

namespace relight::render {

struct RsmTexel {
  std::optional<SurfaceHit> hit;
  Eigen::Vector3f direction = Eigen::Vector3f::Zero();  ///< unit, from the light through the texel
  Eigen::Vector3f flux = Eigen::Vector3f::Zero();
  float importance = 0.f;
  bool occluded_by_virtual = false;
};

struct ReflectiveShadowMap {
  int size = 0;
  std::vector<RsmTexel> texels;  ///< row-major size x size
  [[nodiscard]] std::vector<float> importance() const;
  /// Texels with importance > 0.
  [[nodiscard]] std::size_t covered() const;
};

/// The RSMs of spot light `light` of `scene`: one (both layers) for a virtual light, two (real
/// layer, virtual layer) for a real one. Throws LogicError unless it is a spot light whose cone
/// fits a perspective view (outer half-angle below kMaxRsmHalfAngleDeg) and size is a power of two.
inline constexpr float kMaxRsmHalfAngleDeg = 75.f;
inline constexpr float kMinAlbedo = 0.05f;
[[nodiscard]] std::vector<ReflectiveShadowMap> reflective_shadow_maps_cpu(const MrScene& scene, const RayTracer& tracer,
                                                                         std::size_t light, int size);

/// Whether `light` can be sampled through RSMs (a spot light of at most kMaxRsmHalfAngleDeg).
[[nodiscard]] bool has_reflective_shadow_maps(const MrLight& light);

/// The RSM view of a spot light: the image plane at distance 1 along `axis`, spanned by
/// `tangent` (texel x) and `bitangent` (texel y), [-half_extent, half_extent]² in `size`² texels.
struct RsmView {
  Eigen::Vector3f axis, tangent, bitangent;
  float half_extent = 0.f;
  float texel_side = 0.f;
  int size = 0;
};
/// Throws LogicError (naming `who`) unless `light_index` is a spot light with RSMs and `size` a
/// power of two.
[[nodiscard]] RsmView rsm_view(const MrScene& scene, std::size_t light_index, int size, const char* who);

/// What the ray through one texel meets, as the RSMs need it: `first`, the nearest surface of the
/// layers the light's first RSM sees (both layers for a virtual light, the real layer for a real
/// one), and for a real light `virtual_in_front`, the virtual surface nearer than `first` (or
/// any virtual surface where `first` is empty).
struct RsmTexelHits {
  std::optional<SurfaceHit> first;
  std::optional<SurfaceHit> virtual_in_front;
};
/// The surfaces of texel (x, y), whose ray from the light has unit `direction`.
using RsmTexelHitsFn = std::function<RsmTexelHits(int x, int y, const Eigen::Vector3f& direction)>;

/// The RSMs of spot light `light_index` (one or two, as reflective_shadow_maps_cpu) over `view`,
/// with every texel's direction, flux, importance and occlusion set by the rules of the header
/// comment from the surfaces `hits` reports: the part the ray-cast and rasterised RSMs share.
[[nodiscard]] std::vector<ReflectiveShadowMap> assemble_reflective_shadow_maps(const MrScene& scene,
                                                                               std::size_t light_index,
                                                                               const RsmView& view,
                                                                               const RsmTexelHitsFn& hits);

}  // namespace relight::render
