#pragma once
// Reading and writing virtual-object models: OBJ/MTL (tinyobjloader) and glTF 2.0 (.gltf with
// embedded or external buffers, .glb; tinygltf).
//
// Materials become Phong (k_d, k_s, n) or emissive:
// - MTL: k_d = Kd, k_s = mean of Ks (highlights are white), n = Ns, emission = Ke.
// - glTF: a material's extras {"relight_phong": {"kd": [r, g, b], "ks": s, "n": n}} are taken
//   as they are (relight writes them, so its own models round-trip exactly). Otherwise the
//   metallic-roughness parameters are mapped by phong_from_metallic_roughness() (mr_scene.h):
//   k_d = baseColor (1 - metallic), k_s = 0.04 (1 - metallic) + luminance(baseColor) metallic,
//   and the Phong exponent that matches a Beckmann lobe of slope alpha = roughness^2,
//   n = 2 / alpha^2 - 2 (Walter et al. 2007), clamped to [1, 10000]; emission = emissiveFactor
//   times KHR_materials_emissive_strength.
// glTF base-colour, emissive, metallic-roughness and normal textures (PNG or JPEG; a data URI, a
// GLB buffer view or a file beside the model) become the material's Textures (texture.h) with
// their samplers' wrap modes, and the primitive's TEXCOORD_n (float, or normalised unsigned
// byte/short; one set per material, so its textures must share it) its mesh's texcoords; only
// the images a material uses are decoded, each checked against 8192 px a side from its header
// before decoding (and all of a model's together against 8192^2 texels). The base colour
// multiplies k_d only, so a fully metallic point (k_d = 0) shows no base texture and k_s keeps the
// factor's luminance; the emissive texture multiplies the emission; the metallic-roughness
// texture (linear data: G roughness, B metallic) multiplies the factors and feeds the mapping
// above at each point (surface_phong(); not on materials with relight's own extras); the normal
// texture (with its scale) bends the shading normal in the triangle's tangent frame
// (normal_map.h; TANGENT attributes are not read). Each texture reference's
// KHR_texture_transform (and its texCoord override) is applied (UvTransform, texture.h).
// Specular materials (specular_material.h): a material with KHR_materials_transmission's
// transmissionFactor >= kGltfTransmissionThreshold is glass (a dielectric; partial transmission
// is not modelled) of KHR_materials_ior's index (1.5 without it) and KHR_materials_volume's
// attenuationColor / attenuationDistance (clear without it; the base colour's tint and
// thicknessFactor are not read), its Phong fallback k_d = base (1 - transmission); a material
// with metallic >= kGltfMirrorMinMetallic, roughness <= kGltfMirrorMaxRoughness and no
// metallic-roughness texture is a mirror of reflectance F0 = base colour. save_gltf writes both
// back the same way.
// Occlusion textures, MTL texture maps and the base colour's alpha are ignored. Meshes keep the file's axes
// (y-up, see virtual_model.h); glTF node transforms are applied. save_gltf writes no textures.
#include <array>
#include <filesystem>
#include <string_view>

#include "relight/render/scene/virtual_model.h"

namespace relight::render {

inline constexpr float kGltfTransmissionThreshold = 0.5f;
/// The glTF extensions load_gltf reads; a file using another gets a warning naming it
/// (VirtualModel::warnings).
inline constexpr std::array<std::string_view, 5> kSupportedGltfExtensions{
    "KHR_texture_transform", "KHR_materials_emissive_strength", "KHR_materials_transmission", "KHR_materials_ior",
    "KHR_materials_volume"};
inline constexpr float kGltfMirrorMinMetallic = 0.99f;
inline constexpr float kGltfMirrorMaxRoughness = 0.05f;

/// Loads by extension (.obj, .gltf, .glb). Throws relight::Error with one line naming the file
/// when it is missing, unreadable, malformed or holds no triangles.
[[nodiscard]] VirtualModel load_model(const std::filesystem::path& path);
[[nodiscard]] VirtualModel load_obj(const std::filesystem::path& path);
[[nodiscard]] VirtualModel load_gltf(const std::filesystem::path& path);

/// Writes an OBJ file and its MTL file (same stem) atomically.
void save_obj(const std::filesystem::path& path, const VirtualModel& model);
/// Writes a .gltf with the buffer embedded (base64) atomically, Phong parameters in extras.
void save_gltf(const std::filesystem::path& path, const VirtualModel& model);

}  // namespace relight::render
