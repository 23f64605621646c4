#pragma once
// Shadow maps of the primary lights for the Vulkan DIR renderer (Knecht et al. 2010 use the
// depth of each light's reflective shadow map). Every light is seen through one or six views:
//   spot light, half-angle <= 75 deg  one perspective view along its axis;
//   point light or wider spot          six cube faces (+x, -x, +y, -y, +z, -z);
//   directional light                  one orthographic view over the scene's bounding sphere;
//   light with MrLight::through_vpl    none (its emitter VPL's ISM shadows it).
// Each view is rendered twice, through the real and through the virtual layer, so that the
// shading pass gets V_r and V_v separately (eqs. 5.1-5.5 need min(V_r, V_v) and V_r). The
// virtual layer's views look only at the virtual objects' bounding sphere: the virtual layer
// casts no shadow outside it (a lookup outside a view is unshadowed), and a view over the whole
// room or the whole spot cone gives a small object few texels. A directional light's is the
// orthographic view of that sphere: over a 5 m room, 256-texel tiles are 2 cm each, which
// smeared the objects' contact shadows over the real surface around them. A spot or point
// light's is the perspective view of the cone around the sphere (when the light stands outside
// it and the cone is narrower than the spot's, or than 75 degrees for the six cube faces, which
// then all hold it): the spot of bench dir/specular_640x480 saw its virtual objects through a
// 70-degree view, whose texels made staircases of a glass pebble's shadow edge, a pixel or more
// each.
//
// A texel stores the nearest surface's "light depth": the distance to the light for point and
// spot lights, and the distance along the light's direction for a directional light
// (light_depth()). Texels where nothing is seen hold kShadowEmpty.
//
// The real layer's occluders are the scene's real meshes, or their coarser stand-ins
// MrScene::coarse_real_meshes when it has them: a caster finer than a texel adds triangles to
// rasterise (the rasteriser's cost on a CPU device) but nothing to the map.
//
// The atlas is one float image: `columns` tiles of `tile` x `tile` texels per row, the real
// layer's views first (rows 0..rows-1) and then the virtual layer's. shadow_atlas_cpu() is the
// ray-cast reference of the rasterised atlas (shadow_maps_vk.h); shadow_visibility() is the
// lookup that the shading pass mirrors in GLSL (dir_shade.comp).
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "relight/render/scene/mr_scene.h"
#include "relight/render/reference/ray_tracer.h"

namespace relight::render {

inline constexpr float kShadowEmpty = 1e30f;

struct ShadowView {
  Eigen::Matrix4f world_to_clip;  ///< Vulkan clip space: x right, y down, z in [0, 1]
  /// w = 1: the light's position; w = 0: the unit direction towards the light.
  Eigen::Vector4f eye;
  /// World size of one texel at light depth 1 (perspective) or anywhere (orthographic, w = 0):
  /// the receiver is pushed off its surface by a multiple of it before the lookup.
  float texel_size = 0.f;
};

struct ShadowLayout {
  int tile = 512;
  int columns = 8;
  std::vector<ShadowView> views;          ///< through the real layer
  std::vector<ShadowView> virtual_views;  ///< through the virtual layer, one per entry of `views`
  /// Per MrScene light: first view and view count (1 or 6).
  std::vector<std::array<std::uint32_t, 2>> light_views;

  [[nodiscard]] int rows() const { return (static_cast<int>(views.size()) + columns - 1) / columns; }
  [[nodiscard]] int atlas_width() const { return columns * tile; }
  /// Both layers; at least one row so that an empty atlas is still a valid image.
  [[nodiscard]] int atlas_height() const { return 2 * std::max(rows(), 1) * tile; }
  /// View `index` of layer 0 (real) or 1 (virtual).
  [[nodiscard]] const ShadowView& view(std::size_t index, int layer) const {
    return layer == 0 ? views[index] : virtual_views[index];
  }
  /// Top-left texel of view `view` in layer 0 (real) or 1 (virtual).
  [[nodiscard]] std::array<int, 2> tile_origin(int view, int layer) const {
    return {(view % columns) * tile, (layer * std::max(rows(), 1) + view / columns) * tile};
  }
};

/// The views of every light of `scene` (tile: texels per side, at least 16).
[[nodiscard]] ShadowLayout plan_shadow_views(const MrScene& scene, int tile = 512);

/// What a texel of `view` stores for a surface at `point`.
[[nodiscard]] float light_depth(const ShadowView& view, const Eigen::Vector3f& point);

/// The atlas by casting one ray per texel centre through each layer (row-major floats).
/// `tracer` must hold the occluders the maps see: coarse_scene()'s for a scene with
/// MrScene::coarse_real_meshes.
[[nodiscard]] std::vector<float> shadow_atlas_cpu(const RayTracer& tracer, const ShadowLayout& layout, int threads = 0);

/// How far (metres, along the normal) a real surface point reconstructed from depth may lie from
/// the real mesh's surface: `sigmas` standard deviations of Kinect v1's axial noise at the
/// point's distance `camera_distance` from the camera, sigma(z) = 0.0012 + 0.0019 (z - 0.4)^2
/// (Nguyen, Izadi & Lovell 2012; synth/kinect_noise.h simulates the same). At 2 m that is 6 mm
/// per sigma: against a lamp grazing the table at 20 degrees it is 18 mm of light depth, where
/// the one-texel tolerance of a 25-degree spot's 256-texel map is 4 mm, and the real layer
/// shadowed the table from its own mesh at random pixels (the virtual object's shadow showed the
/// camera's lit table through them). dir_shade.comp mirrors it.
[[nodiscard]] inline float real_surface_tolerance(float sigmas, float camera_distance) {
  const float z = camera_distance - 0.4f;
  return sigmas * (0.0012f + 0.0019f * z * z);
}

/// 1 when `point` (on a surface of unit normal `normal`, facing the light or not) is lit by light
/// `light` through layer `layer` according to `atlas`, else 0. Points outside every view are lit.
/// `surface_tolerance`: how far (metres, along the normal) the receiver may lie from the surface
/// that cast the map (real_surface_tolerance for real points in the real layer, else 0); the
/// depth test allows it along the light's ray, surface_tolerance / cos(incidence) (at most 5x).
[[nodiscard]] float shadow_visibility(const ShadowLayout& layout, std::span<const float> atlas, std::uint32_t light,
                                      int layer, const Eigen::Vector3f& point, const Eigen::Vector3f& normal,
                                      float surface_tolerance = 0.f);

/// shadow_visibility() for the many points of a frame: what depends only on the light and the
/// layer (its views, where their tiles lie in the atlas, a distant light's unit direction) is
/// worked out once, not per lookup. The CPU shading asks it 16 times a pixel (8 probe lights,
/// two layers). Same results as shadow_visibility(), bit for bit (it is that function).
class ShadowLookup {
 public:
  /// Keeps references to both: they must outlive the lookup.
  ShadowLookup(const ShadowLayout& layout, std::span<const float> atlas);
  [[nodiscard]] float operator()(std::uint32_t light, int layer, const Eigen::Vector3f& point,
                                 const Eigen::Vector3f& normal, float surface_tolerance = 0.f) const;

 private:
  struct View {
    const ShadowView* view = nullptr;
    const float* texels = nullptr;  ///< the tile's top-left texel in the atlas
  };
  struct Light {
    std::uint32_t first = 0, count = 0;
    bool positional = false;
    Eigen::Vector3f eye = Eigen::Vector3f::Zero();           ///< position, or the direction towards the light
    Eigen::Vector3f unit_towards = Eigen::Vector3f::Zero();  ///< a distant light's eye, normalised
  };
  int tile_ = 0;
  std::size_t atlas_width_ = 0;
  std::array<std::vector<View>, 2> views_;    ///< per layer, per view of the layout
  std::array<std::vector<Light>, 2> lights_;  ///< per layer, per light of the layout
};

}  // namespace relight::render
