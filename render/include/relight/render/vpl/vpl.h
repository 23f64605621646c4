#pragma once
// Virtual point lights (VPLs) for differential instant radiosity (Knecht et al., ISMAR 2010;
// dissertation §5.2.3-5.2.6).
//
// A VPL is a point where light from a primary light (or from another VPL) is reflected. In
// differential rendering every light path exists in up to two worlds: the real+virtual world
// (L_rv) and the real-only world (L_r). A VPL records which:
//   in_real_virtual  the path to it is valid with the virtual objects present,
//   in_real          the path to it is valid without them (real light, real vertices only).
// In Knecht's notation r(x̄)·r(VPL) = in_real and (1 - ir(VPL)) = in_real_virtual; a VPL with
// in_real and not in_real_virtual is the "illuminate real only" VPL (VPL3 of Fig. 5.7): the
// real surface behind a virtual object keeps its light in L_r, so that the difference removes
// its colour bleeding from the camera image.
//
// Generation: each light sample is traced against the real layer and the virtual layer (the two
// RSMs of a real spot light). If the real hit is nearer, one VPL holds both flags of its parent;
// if a virtual object is in front, the virtual hit becomes a VPL of the real+virtual world and
// the real hit a VPL of the real-only world. Multi-bounce VPLs continue from a VPL by importance
// sampling its Phong BRDF (phong_brdf.h), and flags multiply along the path. Where the sampled
// direction lands is found by a ray (BounceMethod::RayTraced) or, as in the dissertation's
// GPU-friendly multi-bounce method (§5.2.7), among surface points (BounceMethod::PointCone):
// area-uniform points on the real and on the virtual surfaces (sample_ism_points) are the
// candidates, those within `cone_half_angle_deg` of the direction compete and the nearest wins
// (cone_search.h has the exact rules), per layer, with the same two-world rule as a ray: a
// virtual candidate nearer than the real one takes the real+virtual flags and the real one the
// real-only flags. No ray tracer is needed beyond the first bounce, and the search is a
// min-reduction over points, which a GPU does in one work group per query (cone_search_vk.h).
// A direction whose cone holds no point ends the path (a ray would have found a surface there),
// so sparse points lose energy: the pool must hold enough points that a cone's footprint at the
// scene's distances covers several.
//
// The multiple-bounce light source (BounceMethod::PreviousFrame; Knecht et al. 2010 §4.3 and
// §5.2, the dissertation's first method of §5.2.7): a share of each frame's light samples
// (`bounce_share`) continues the paths of the previous frame's VPLs instead of following this
// frame's in turn. Each sample picks a source VPL with probability proportional to its flux's
// luminance (stratified over the samples), samples a direction from the source's BRDF and traces
// it through both layers as any bounce (flags multiply as above), so the new VPL carries
// flux / (p N_bounce) times the BRDF sample's weight. A source of bounce k gives a VPL of bounce
// k + 1, up to `bounces`: the bounces build up over frames at the cost of one segment per
// sample. Where the paper renders the scene's point cloud into the slots and keeps, per slot,
// the point that the source lights most (its depth test; it notes itself that choosing by
// probability would be better) with visibility from the previous frame's ISMs, we trace the
// sampled direction: the estimate is unbiased for a static scene and the visibility exact. The
// price is the paper's too: the light of the previous frame's VPLs lags one frame behind a
// change (a switched lamp's second bounce lingers for a frame, the third for two). The first
// frame, without a previous one, gives every sample to the primary lights.
//
// Mirrors and glass (specular_material.h) hold no VPL: a path that meets one goes on in the
// mirrored or refracted direction (chosen in proportion to Fresnel; Beer-Lambert inside) to the
// diffuse surface it reaches, where the VPL is left - the caustic VPLs of Knecht et al., TVCG 2013
// §4.2.2, which light the surroundings with the light the object focuses (vpl_tracer.h,
// follow_specular). Ray-traced bounces only; the rasterised RSMs do not yet.
//
// Virtual focus: the differential image lives where virtual objects reflect or block light, and
// they are small, so uniformly spread light samples put few VPLs on them. A share of each light's
// samples (`virtual_share`) is therefore drawn uniformly inside the cone that the virtual objects'
// bounding sphere subtends from the light (flux I Omega_cone / n_cone each); the other samples
// are drawn over the light's whole emission and dropped when they fall into that cone (flux
// I Omega_light / n_rest each). The two strata cover every direction once: unbiased.
//
// Emitters: a directional light with MrLight::through_vpl (the environment light of Knecht et al.
// 2010 §3.6 and §5.2, dissertation §5.2.7) also gets one VPL of bounce 0 that lights surfaces directly.
// The paper places such VPLs on a hemisphere around the scene centre, which gives light from
// infinitely far away an inverse-square falloff and a parallax across the scene; ours is a
// directional emitter: it delivers the light's irradiance E (its `flux`, W/m^2) from `incident`
// at every point, L_o = E f_x cos(theta_x), and only its imperfect shadow map needs a position,
// far out along the light (kEmitterDistance scene radii from the scene's centre), from where its
// tiles are nearly orthographic views of the scene and of the virtual objects (ism.h). The
// paper also interleaves them with the bounce VPLs; the renderers here shade every emitter at
// every pixel, as direct light (dir.h): spread over the 4 x 4 merge window, a glossy virtual
// object's sunlit highlight and a shadow's edge came out blocky (the stage test measured 19.8
// levels of mean difference to the shadow-mapped sun on the pebble; 0.7 unmerged), and an
// emitter costs a pixel only two ISM lookups.
//
// Flux (W, RGB): a light of intensity I sampled with density p(omega) over N samples gives each
// first-bounce VPL Phi = I(omega) / (p(omega) N), so that its contribution to a point x is
//   Phi f_y(omega_in, y->x) f_x(y->x, omega_o) cos(theta_y) cos(theta_x) / |x - y|^2.
#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "relight/core/named_values.h"
#include "relight/render/reference/ray_tracer.h"
#include "relight/render/scene/mr_scene.h"

namespace relight::render {

struct Vpl {
  Eigen::Vector3f position;
  Eigen::Vector3f normal;    ///< unit, on the side the light arrived from
  /// The surface's geometric normal on that side: a continued path leaves above it (the shading
  /// normal may tilt below the surface, where no light goes).
  Eigen::Vector3f geometric_normal = Eigen::Vector3f::UnitZ();
  Eigen::Vector3f incident;  ///< unit, from the VPL towards where its light came from
  Eigen::Vector3f flux;
  std::uint32_t material = 0;
  /// The factor of the material's k_d from its base-colour texture at the VPL (1: untextured).
  Eigen::Vector3f kd_texture = Eigen::Vector3f::Ones();
  /// The material's metallic-roughness texture at the VPL (surface_phong(); 1: none).
  Eigen::Vector3f metallic_roughness = Eigen::Vector3f::Ones();
  bool on_real_surface = true;  ///< r(VPL)
  bool in_real_virtual = true;
  bool in_real = true;
  int bounce = 1;           ///< 1 = lit directly by a primary light; 0 = an emitter (see the header)
  std::uint32_t light = 0;  ///< index of the primary light (MrScene::lights) the path started at
  static constexpr std::uint32_t kNoParent = 0xffffffffu;
  std::uint32_t parent = kNoParent;  ///< index (in the generated list) of the VPL this one continues

  [[nodiscard]] bool emitter() const { return bounce == 0; }
};

/// The Phong parameters of the surface a VPL lies on (its material, textured at the VPL).
[[nodiscard]] inline Phong vpl_phong(const MrScene& scene, const Vpl& vpl) {
  return with_kd_factor(surface_phong(scene.materials[vpl.material], vpl.metallic_roughness), vpl.kd_texture);
}

/// How far out along its light an emitter VPL sits, in radii of the scene's bounding sphere.
inline constexpr float kEmitterDistance = 100.f;

/// How many emitters end `vpls` (generate_vpls puts them last); throws relight::Error when an
/// emitter comes before a bounce VPL, which the renderers' loops rely on.
[[nodiscard]] std::size_t emitter_count(std::span<const Vpl> vpls);

/// How the `count` light samples are shared among the lights (dissertation §5.2.3). Whatever the
/// shares, each light's VPLs carry its whole emitted flux (flux per sample = power / samples), so
/// the budget moves noise between lights, not energy.
///   Equal           the same number per light;
///   ByPower         proportional to emitted power (luminance x solid angle, or x the scene's
///                   cross-section for a directional light);
///   ByWeight        proportional to `light_weights` (one per light; missing entries count 1);
///   ByPreviousFlux  proportional to the flux the light's VPLs carried last frame
///                   (`previous_flux`, from vpl_flux_per_light), i.e. the light that actually
///                   reached surfaces: a spot light aimed past the scene gets few samples. Without
///                   any (the first frame) the shares are equal, as the dissertation's default
///                   mode (§5.2.7); a light without an entry takes its ByPower weight scaled to
///                   the others, and every light keeps at least 1/16 of the mean share so that
///                   one that found nothing last frame can recover.
enum class VplBudget { Equal, ByPower, ByWeight, ByPreviousFlux };
inline constexpr std::array<NamedValue<VplBudget>, 4> kVplBudgetNames{{{"equal", VplBudget::Equal},
                                                                       {"power", VplBudget::ByPower},
                                                                       {"weights", VplBudget::ByWeight},
                                                                       {"flux", VplBudget::ByPreviousFlux}}};

/// Where a spot light's first-bounce VPLs come from.
///   RayTraced             light samples traced against both layers (above), for every light;
///   ReflectiveShadowMaps  importance-sampled texels of the spot light's RSMs
///                         (reflective_shadow_map.h: ray cast on the CPU, or rasterised by
///                         VplGpu::reflective_shadow_maps) by hierarchical warping of a Hammersley set
///                         (hierarchical_warp.h), flux = texel flux / (probability x slots); a
///                         real light's slots are shared between its real and virtual RSM by the
///                         texels each covers. virtual_share does not apply (the virtual RSM is the
///                         focus), and lights without RSMs (point, directional, spots wider than
///                         75 degrees) stay ray traced. Further bounces are traced as above.
enum class VplSource { RayTraced, ReflectiveShadowMaps };
inline constexpr std::array<NamedValue<VplSource>, 2> kVplSourceNames{
    {{"rays", VplSource::RayTraced}, {"rsm", VplSource::ReflectiveShadowMaps}}};

/// How a VPL's continued light path finds its next surface (bounces ≥ 2; see the header comment):
/// within the frame by a ray or a point-cone search, or a frame later from the previous frame's
/// VPLs (the multiple-bounce light source).
enum class BounceMethod { RayTraced, PointCone, PreviousFrame };
inline constexpr std::array<NamedValue<BounceMethod>, 3> kBounceMethodNames{
    {{"rays", BounceMethod::RayTraced},
     {"cone", BounceMethod::PointCone},
     {"previous-frame", BounceMethod::PreviousFrame}}};

struct VplOptions {
  int count = 256;      ///< first-bounce light samples (each may yield two VPLs, see above)
  int bounces = 1;      ///< 1 = one indirect bounce; 2 adds VPLs lit by VPLs
  VplBudget budget = VplBudget::ByPower;
  float virtual_share = 0.5f;  ///< of each light's samples aimed at the virtual objects (0 = off)
  std::uint64_t seed = 1;
  std::vector<float> light_weights{};   ///< VplBudget::ByWeight
  std::vector<double> previous_flux{};  ///< VplBudget::ByPreviousFlux
  VplSource source = VplSource::RayTraced;
  int rsm_size = 256;  ///< VplSource::ReflectiveShadowMaps: texels per side, a power of two
  BounceMethod bounce_method = BounceMethod::RayTraced;
  float cone_half_angle_deg = 5.f;  ///< BounceMethod::PointCone: the dissertation's 5 degrees
  int cone_points = 16384;          ///< BounceMethod::PointCone: candidate points per layer (<= 65536)
  /// BounceMethod::PreviousFrame: the share of `count` that continues the previous frame's VPLs,
  /// in (0, 1), and those VPLs with the Phong parameters of their surfaces (VplSet); empty on
  /// the first frame.
  float bounce_share = 0.25f;
  std::span<const Vpl> previous_vpls{};
  std::span<const Phong> previous_surfaces{};
};

/// One frame's VPLs, as a frame-graph buffer, with the Phong parameters of each one's surface
/// (vpl_phong when it was made): the next frame's scene has materials of its own, so the
/// multiple-bounce light source continues a previous VPL's path with these.
struct VplSet {
  std::vector<Vpl> vpls;
  std::vector<Phong> surfaces;  ///< one per VPL where the next frame continues them, else empty
  static constexpr const char* type_name = "VplSet";
};

/// vpl_phong of every VPL: VplSet::surfaces.
[[nodiscard]] std::vector<Phong> vpl_surfaces(const MrScene& scene, std::span<const Vpl> vpls);

class ConeSearchVk;
class ReflectiveShadowMapsVk;

/// The GPU engines VPL generation may use, each optional: the point-cone search of the
/// bounces, and the rasterised RSMs of VplSource::ReflectiveShadowMaps (which must have been
/// given the scene, ReflectiveShadowMapsVk::set_scene). Without them the CPU references run.
struct VplGpu {
  ConeSearchVk* cone_search = nullptr;
  ReflectiveShadowMapsVk* reflective_shadow_maps = nullptr;
};

/// Per light of the scene, the luminance of the flux its first-bounce VPLs carry (the input of
/// VplBudget::ByPreviousFlux for the next frame).
[[nodiscard]] std::vector<double> vpl_flux_per_light(const std::vector<Vpl>& vpls, std::size_t light_count);

/// VPLs of every light of `scene`. A directional light (the environment lights of the light-
/// extraction stage) shoots parallel rays from a disk facing it that covers the scene's bounding
/// sphere, each carrying irradiance x disk area / samples. Ray-traced bounces follow each path to
/// its end before the next (a VPL's continuations come right after it); BounceMethod::PointCone
/// resolves all paths of one bounce together, one search per layer, on gpu.cone_search when
/// given (its points are replaced), so the list holds all first bounces, then all second
/// bounces, and so on. Vpl::parent links them either way. The emitters of the lights with
/// MrLight::through_vpl come last, one per light, whatever the count.
[[nodiscard]] std::vector<Vpl> generate_vpls(const MrScene& scene, const RayTracer& tracer, const VplOptions& options,
                                             const VplGpu& gpu = {});

}  // namespace relight::render
