#pragma once
// MrScene: the mixed-reality scene that both the reference path tracer and the DIR renderer
// consume (Knecht's dissertation §5.2). Everything is in the world frame (metres, linear RGB).
//
// Every mesh and every light carries the real/virtual flag r(x) of differential rendering:
// L_rv is the light transport of the whole scene, L_r that of the real elements alone (virtual
// meshes invisible to every ray, virtual lights switched off). Real geometry comes from the
// synthetic scene's exact shapes (truth/scene_from_synth.h) or from the reconstructed depth of a frame
// (depth_mesh.h); virtual objects from OBJ/glTF files (model_io.h).
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "relight/core/camera.h"
#include "relight/core/phong.h"
#include "relight/core/pose.h"
#include "relight/render/scene/specular_material.h"
#include "relight/render/scene/texture.h"

namespace relight::render {

/// glTF 2.0's metallic-roughness parameters and relight's mapping of them to Phong (model_io.h):
/// k_d = base (1 - metallic), k_s = 0.04 (1 - metallic) + luminance(base) metallic, and the
/// Phong exponent of a Beckmann lobe of slope alpha = roughness^2, n = 2 / alpha^2 - 2 (Walter
/// et al. 2007), clamped to [1, 10000].
struct MetallicRoughness {
  Eigen::Vector3f base_color{1.f, 1.f, 1.f};
  float metallic = 1.f;
  float roughness = 1.f;
};
[[nodiscard]] Phong phong_from_metallic_roughness(const MetallicRoughness& parameters);

/// A material of the scene: relight's Phong model (core/phong.h; sampled in phong_brdf.h), a name,
/// an emitted radiance (a virtual light source shaped like its mesh) and, optionally, textures
/// read at each surface point (texture.h; the triangles need texture coordinates): a base colour
/// that multiplies k_d and an emission texture that multiplies the emission, per channel, and a
/// metallic-roughness texture (glTF's: G roughness, B metallic, linear) whose values multiply
/// `metallic_roughness`'s factors and give k_d (before the base colour), k_s and n through the
/// mapping above, and a normal texture (glTF's, linear; normal_map.h) that bends the shading
/// normal, its x and y times `normal_scale`. Textures are shared: scenes are copied every frame,
/// texels are not. A `specular` material (a mirror, a metal, glass: specular_material.h) is
/// perfectly specular for the renderers that model it (the path tracer); the others shade its
/// Phong fallback.
struct PhongMaterial : Phong {
  std::string name;
  Eigen::Vector3f emission{0.f, 0.f, 0.f};
  std::shared_ptr<const Texture> base_color{};
  std::shared_ptr<const Texture> emission_texture{};
  std::shared_ptr<const Texture> metallic_roughness_texture{};
  MetallicRoughness metallic_roughness{};  ///< the factors; read only with metallic_roughness_texture
  std::shared_ptr<const Texture> normal_texture{};
  float normal_scale = 1.f;
  SpecularMaterial specular{};
};

/// `material`'s Phong parameters at a point where its metallic-roughness texture reads
/// `metallic_roughness_texel` (texture_at()), before the base-colour texture; the material's
/// own without that texture.
[[nodiscard]] Phong surface_phong(const PhongMaterial& material, const Eigen::Vector3f& metallic_roughness_texel);

/// What is wrong with a material's specular part (a mirror's reflectance outside [0, 1]; glass
/// with an index of refraction outside [1, 4] or NaN, an attenuation colour outside (0, 1], an
/// attenuation distance not above 0), as one line naming the material; none when it is valid.
[[nodiscard]] std::optional<std::string> specular_problem(const PhongMaterial& material);

/// A texture's colour at a point with coordinates `uv` (mip level `lod`), or its mean where the
/// point has none; 1 without a texture.
[[nodiscard]] Eigen::Vector3f texture_at(const Texture* texture, const Eigen::Vector2f* uv, float lod = 0.f);

/// `material`'s Phong parameters with k_d multiplied per channel by `factor` (its texture's
/// colour at a surface point).
[[nodiscard]] Phong with_kd_factor(const Phong& material, const Eigen::Vector3f& factor);

/// An indexed triangle mesh with one material per triangle. `normals` is either empty (flat
/// shading with the geometric normal) or one unit normal per vertex (interpolated); `texcoords`
/// is either empty or one texture coordinate per vertex (interpolated; glTF's TEXCOORD of the
/// material's base-colour texture).
struct TriangleMesh {
  std::string name;
  std::vector<Eigen::Vector3f> positions;
  std::vector<Eigen::Vector3f> normals;
  std::vector<Eigen::Vector2f> texcoords;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  std::vector<std::uint32_t> triangle_material;  ///< index into MrScene::materials
  bool real = true;                              ///< r(x): measured surface or virtual object

  [[nodiscard]] std::size_t triangle_count() const { return triangles.size(); }
};

enum class LightKind { Point, Spot, Directional };

/// A primary light. Point and spot lights have a radiant intensity `intensity` (W/sr, RGB);
/// a spot light scales it by a smooth falloff between cos_inner (full) and cos_outer (zero)
/// around `direction`. A directional light delivers the irradiance `intensity` (W/m^2, RGB) to a
/// surface facing it, coming from `direction` (unit, towards the light) - the environment
/// lights of the light-extraction stage.
///
/// `through_vpl` (directional lights only) is the environment light of Knecht et al. 2010 §5.2
/// and the dissertation §5.2.7: the light reaches surfaces through an emitter VPL (vpl.h,
/// bounce 0) shadowed by that VPL's imperfect shadow map, like every other VPL, instead of
/// through the direct pass and its two shadow maps. The path tracer is unaffected.
struct MrLight {
  LightKind kind = LightKind::Point;
  Eigen::Vector3f position{0.f, 0.f, 0.f};
  Eigen::Vector3f direction{0.f, 0.f, -1.f};
  Eigen::Vector3f intensity{1.f, 1.f, 1.f};
  float cos_inner = 0.9f;
  float cos_outer = 0.8f;
  bool real = true;
  bool through_vpl = false;
};

/// A spot light at `position` shining along `direction` (stored as given), at full intensity
/// within `inner_deg` of its axis and fading to zero at `outer_deg`.
[[nodiscard]] MrLight spot_light(const Eigen::Vector3f& position, const Eigen::Vector3f& direction, float outer_deg,
                                 float inner_deg, const Eigen::Vector3f& intensity, bool real);

/// Radiance arriving from every direction where a ray leaves the scene (real: it is part of the
/// camera's world, like the synthetic scene's open sky).
struct Environment {
  Eigen::Vector3f radiance{0.f, 0.f, 0.f};
};

/// A sphere around geometry; radius < 0 when there is none.
struct BoundingSphere {
  Eigen::Vector3f centre = Eigen::Vector3f::Zero();
  float radius = -1.f;
};

struct MrScene;

enum class SceneMeshes { All, Virtual, Specular };
/// A sphere around every vertex of `scene`'s meshes (or of its virtual ones, or of its triangles
/// with a specular material): the bounding box's half diagonal, 1 % + 1 mm larger.
[[nodiscard]] BoundingSphere bounding_sphere(const MrScene& scene, SceneMeshes meshes = SceneMeshes::All);

struct MrScene {
  std::vector<PhongMaterial> materials;
  std::vector<TriangleMesh> meshes;
  std::vector<MrLight> lights;
  Environment environment;
  /// Empty, or a coarser tessellation of the real meshes (e.g. the reconstruction on a wider
  /// grid, depth_mesh.h, whose vertices are a subset of the full mesh's) that stands in for them
  /// where light transport is sampled more coarsely than the camera's pixels: as the occluders of
  /// the primary lights' shadow maps (shadow_maps.h) and as the surfaces the VPLs are traced onto
  /// (vpl.h). The G-buffer, the ISMs and the path tracer see `meshes`.
  std::vector<TriangleMesh> coarse_real_meshes;

  /// Adds a material and returns its index.
  std::uint32_t add_material(PhongMaterial material);
  [[nodiscard]] std::size_t triangle_count(bool real) const;
  /// Throws relight::Error when a mesh (coarse or not) refers to a missing material or vertex,
  /// or has a non-finite position, or a normal array of the wrong size, or a coarse mesh is
  /// virtual, or a specular material is out of range (reflectance and attenuation colour in
  /// [0, 1], the attenuation colour above 0, ior in [1, 4], attenuation distance > 0).
  void validate() const;

  static constexpr const char* type_name = "MrScene";
};

/// `scene` with its coarse_real_meshes in place of its real meshes (when it has any), its
/// virtual meshes as they are.
[[nodiscard]] MrScene coarse_scene(const MrScene& scene);

/// The camera of one frame: pinhole intrinsics (with the image size) and camera-to-world pose
/// (OpenCV camera convention: x right, y down, z forward).
struct MrCamera {
  PinholeIntrinsics intrinsics;
  Pose camera_to_world = Pose::Identity();
};

}  // namespace relight::render
