#pragma once
// Imperfect shadow maps (Ritschel et al. 2008) as the DIR renderer uses them (Knecht's
// dissertation §5.2.8): the visibility of every VPL from a low-resolution hemispherical depth
// map rendered from a sparse point sampling of the scene.
//
// Points: two pools of area-uniform samples, one on the real and one on the virtual surfaces
// (giving V_r and V_v separately, eqs. 5.6-5.8). Each VPL splats `points_per_vpl` points of each
// pool - a contiguous run of the shuffled pool that starts at a different place for every VPL -
// so each point stands for area / points_per_vpl of its layer. The virtual objects are small,
// and their own pool keeps them densely sampled where a shared pool would leave them nearly empty.
//
// Splats: each point is a square of that area in its tangent plane (aligned to the surface
// normal, §5.2.8). Its four corners are mapped into the VPL's tile with the paraboloid mapping
// of the hemisphere around the VPL normal, (u, v) = (x, y) / (1 + z) in the VPL's frame
// (orthonormal_basis()); every texel centre inside the mapped quad (at most kMaxSplat texels
// across) and the texel under the point itself keep the minimum distance VPL -> point.
//
// Virtual focus: the virtual objects are small, and a hemisphere of tile x tile texels gives
// them a few texels at best, so their shadows come out blocky or vanish under the depth bias.
// A VPL outside the virtual objects' bounding sphere therefore maps its *virtual* tile as a
// perspective view of the cone around that sphere (every virtual point lies inside it); the
// real tile keeps the hemisphere. Directions outside the cone see nothing virtual (V_v = 1).
//
// Emitters (vpl.h, bounce 0) light the scene from far away: a hemisphere around them would
// squeeze the scene into a few texels, so both their tiles are perspective views, the real one
// of the cone around every point of the pools (IsmPointPools::scene_bounds) and the virtual one
// of the cone around the virtual objects (or the scene's when the focus is off). From
// kEmitterDistance scene radii these are nearly orthographic, like a directional light's
// shadow map, at the ISM's resolution and built from the same points. Seen so, the points are
// spread evenly over the tile (no hemisphere's crowding near the VPL), the holes between splats
// are single texels, and their tiles are filled from one coarser level only
// (kEmitterPullPushLevels): more levels grew the virtual silhouette by up to a coarse texel and
// filled holes on a slanted floor with depths nearer than the bias (measured,
// environment_vpl_test.cpp: with 3 levels 166 shadowed floor pixels against 131 exact and 3 of
// 190 lit pixels self-shadowed; with 1, 130 and none; none filled: 113, light through holes).
//
// Holes: pull-push (Marroquim et al. 2007): a coarser texel averages its valid children and is
// valid when at least two are; holes of a finer level take their parent's value. Requiring two
// children keeps the fill from growing a lone occluder's silhouette into empty space.
//
// Atlas layout (floats, kShadowEmpty where nothing is seen): tile t = layer * vpl_count + vpl,
// layer 0 real and 1 virtual, texel (x, y) at (t * tile + y) * tile + x. ism_atlas_cpu() is the
// reference of the Vulkan splat + pull-push (ism_vk.h); IsmLookup is the lookup that the
// shading pass mirrors in GLSL (dir_shade.comp).
#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "relight/render/scene/mr_scene.h"
#include "relight/render/vpl/surface_points.h"
#include "relight/render/vpl/vpl.h"

namespace relight::render {

inline constexpr int kMaxSplat = 16;

/// The pull-push levels of an emitter's tiles (at most IsmOptions::pull_push_levels; see above).
inline constexpr int kEmitterPullPushLevels = 1;

/// The lookup's depth bias is two texels' worth of the tile's angle plus a constant: 2 cm for a
/// VPL's tiles, whose hemisphere spreads the scene thin and whose real points stand for noisy
/// reconstructed surfaces; 2 mm for an emitter's virtual tile, a near-orthographic view of the
/// virtual objects' exact surfaces. There the 2 cm took the umbra of a small object: a pebble
/// 3 cm tall shadows table points that lie within a few centimetres of it along the light
/// (measured on the synthetic room at the path tracer's umbra pixels, L_rv / L_r: 8 emitters
/// 0.27 with 2 cm, 0.13 with 2 mm; 64 emitters 0.28, 0.19; the path tracer 0.08, 8
/// shadow-mapped lights 0.12).
inline constexpr float kIsmBias = 0.02f;
inline constexpr float kEmitterVirtualIsmBias = 0.002f;

struct IsmOptions {
  int tile = 64;               ///< texels per side of one VPL's map
  int points_per_vpl = 1024;   ///< per layer
  int pool_factor = 16;        ///< pool size = pool_factor * points_per_vpl per layer
  int pull_push_levels = 3;    ///< coarser levels used to fill holes (tile >> levels >= 2)
  bool focus_virtual = true;   ///< the virtual tile looks at the virtual objects only (above)
  std::uint64_t seed = 7;
};

/// How one VPL's tile maps directions: the paraboloid of the hemisphere around the VPL normal
/// (tan_half = 0), or a perspective view of the cone of half-angle atan(tan_half) around axis n.
struct TileProjection {
  Eigen::Vector3f origin, t, b, n;
  float tan_half = 0.f;

  [[nodiscard]] static TileProjection hemisphere(const Vpl& vpl);
  /// The view of `sphere` (centre, radius) from the VPL; the hemisphere when the VPL is inside
  /// or near the sphere, or the radius is 0.
  [[nodiscard]] static TileProjection towards(const Vpl& vpl, const Eigen::Vector4f& sphere);
  /// The mapping of VPL `vpl`'s real tile (layer 0) and of its virtual tile (layer 1).
  [[nodiscard]] static TileProjection real_tile(const Vpl& vpl, const IsmPointPools& points);
  [[nodiscard]] static TileProjection virtual_tile(const Vpl& vpl, const IsmPointPools& points);

  /// Unit direction towards `p` in the (t, b, n) frame, and its distance.
  [[nodiscard]] Eigen::Vector3f local(const Eigen::Vector3f& p, float& distance) const;
  /// Texel coordinates of a local direction; for a perspective view, false when it lies
  /// outside the view.
  [[nodiscard]] bool texel(const Eigen::Vector3f& local_direction, int tile, Eigen::Vector2f& coordinates) const;
  /// The local unit direction through texel coordinates.
  [[nodiscard]] Eigen::Vector3f direction(const Eigen::Vector2f& coordinates, int tile) const;
  /// Angle spanned by one texel at the centre of the tile (radians).
  [[nodiscard]] float texel_angle(int tile) const;
};

/// Area-uniform points on the real and on the virtual triangles of `scene` (shuffled).
[[nodiscard]] IsmPointPools sample_ism_points(const MrScene& scene, const IsmOptions& options);

/// Index into a pool of point `i` of VPL `vpl`'s run.
[[nodiscard]] inline std::uint32_t ism_point_index(std::uint32_t vpl, std::uint32_t i, std::uint32_t pool_size) {
  return static_cast<std::uint32_t>((static_cast<std::uint64_t>(vpl) * 7919u + i) % pool_size);
}

/// Splats and pull-push on the CPU: the atlas of `vpls` (2 * vpls.size() tiles).
[[nodiscard]] std::vector<float> ism_atlas_cpu(const IsmPointPools& points, std::span<const Vpl> vpls,
                                               const IsmOptions& options);

/// Visibility lookups in an ISM atlas. Both layers share the texel, so one lookup answers V_r and
/// V_v; each VPL's frame is computed once. The depth bias grows with the distance and the tile's
/// angular texel size.
class IsmLookup {
 public:
  /// `points`: the pools the atlas was splatted from (for their bounds).
  IsmLookup(std::span<const float> atlas, const IsmOptions& options, std::span<const Vpl> vpls,
            const IsmPointPools& points);

  struct Visibility {
    float real = 1.f;     ///< V_r
    float virtual_ = 1.f; ///< V_v
  };
  /// Whether `point` is visible from VPL `index` through each layer.
  [[nodiscard]] Visibility operator()(std::uint32_t index, const Eigen::Vector3f& point) const;
  /// The same, for a caller that has the offset from the VPL to the point and its length already
  /// (the shading loop's light direction): both layers' lookups reuse them.
  [[nodiscard]] Visibility operator()(std::uint32_t index, const Eigen::Vector3f& from_vpl, float distance) const;

 private:
  [[nodiscard]] float visible(const TileProjection& projection, std::size_t tile_offset,
                              const Eigen::Vector3f& from_origin, float distance, float constant_bias) const;

  std::span<const float> atlas_;
  int tile_;
  std::size_t layer_stride_;
  std::vector<TileProjection> real_, virtual_;
  std::vector<bool> emitter_;  ///< per VPL: its virtual tile takes kEmitterVirtualIsmBias
};

/// Texel coordinates in [0, tile) of `direction` (unit, VPL frame, z along the VPL normal).
[[nodiscard]] Eigen::Vector2f paraboloid_texel(const Eigen::Vector3f& local_direction, int tile);
/// The inverse: the unit direction (VPL frame) through texel coordinates (e.g. a texel centre).
[[nodiscard]] Eigen::Vector3f paraboloid_direction(const Eigen::Vector2f& texel, int tile);

}  // namespace relight::render
