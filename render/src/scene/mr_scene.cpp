#include "relight/render/scene/mr_scene.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "relight/core/error.h"

namespace relight::render {

MrLight spot_light(const Eigen::Vector3f& position, const Eigen::Vector3f& direction, float outer_deg, float inner_deg,
                   const Eigen::Vector3f& intensity, bool real) {
  MrLight light;
  light.kind = LightKind::Spot;
  light.position = position;
  light.direction = direction;
  light.cos_outer = std::cos(outer_deg * std::numbers::pi_v<float> / 180.f);
  light.cos_inner = std::cos(inner_deg * std::numbers::pi_v<float> / 180.f);
  light.intensity = intensity;
  light.real = real;
  return light;
}

Eigen::Vector3f texture_at(const Texture* texture, const Eigen::Vector2f* uv, float lod) {
  if (!texture) return Eigen::Vector3f::Ones();
  return uv ? texture->sample(uv->x(), uv->y(), lod) : texture->mean();
}

Phong with_kd_factor(const Phong& material, const Eigen::Vector3f& factor) {
  Phong out = material;
  out.kd = out.kd.cwiseProduct(factor);
  return out;
}

Phong phong_from_metallic_roughness(const MetallicRoughness& parameters) {
  const float metallic = std::clamp(parameters.metallic, 0.f, 1.f);
  const float roughness = std::clamp(parameters.roughness, 0.f, 1.f);
  const Eigen::Vector3f& base = parameters.base_color;
  Phong out;
  out.kd = base * (1.f - metallic);
  out.ks = 0.04f * (1.f - metallic) + (0.2126f * base.x() + 0.7152f * base.y() + 0.0722f * base.z()) * metallic;
  const float alpha = std::max(1e-3f, roughness * roughness);
  out.n = std::clamp(2.f / (alpha * alpha) - 2.f, 1.f, 10000.f);
  return out;
}

std::optional<std::string> specular_problem(const PhongMaterial& material) {
  const SpecularMaterial& s = material.specular;
  const auto unit = [](const Eigen::Vector3f& c) {
    return c.allFinite() && c.minCoeff() >= 0.f && c.maxCoeff() <= 1.f;
  };
  if (s.kind == SpecularKind::Conductor && !unit(s.reflectance))
    return "material '" + material.name + "': a mirror's reflectance must lie in [0, 1]";
  if (s.kind == SpecularKind::Dielectric &&
      (!(s.ior >= 1.f && s.ior <= 4.f) || !unit(s.attenuation_color) || !(s.attenuation_color.minCoeff() > 0.f) ||
       !(s.attenuation_distance > 0.f)))
    return "material '" + material.name +
           "': glass needs an index of refraction in [1, 4] (this one: " + std::to_string(s.ior) +
           "), an attenuation colour in (0, 1] and an attenuation distance above 0";
  return std::nullopt;
}

Phong surface_phong(const PhongMaterial& material, const Eigen::Vector3f& metallic_roughness_texel) {
  if (!material.metallic_roughness_texture) return material;
  MetallicRoughness at = material.metallic_roughness;
  at.roughness *= metallic_roughness_texel.y();
  at.metallic *= metallic_roughness_texel.z();
  return phong_from_metallic_roughness(at);
}

std::uint32_t MrScene::add_material(PhongMaterial material) {
  materials.push_back(std::move(material));
  return static_cast<std::uint32_t>(materials.size() - 1);
}

std::size_t MrScene::triangle_count(bool real) const {
  std::size_t count = 0;
  for (const TriangleMesh& mesh : meshes)
    if (mesh.real == real) count += mesh.triangle_count();
  return count;
}

namespace {

void validate_mesh(const TriangleMesh& mesh, std::size_t material_count) {
  const std::string where = "mesh '" + mesh.name + "': ";
  if (mesh.triangle_material.size() != mesh.triangles.size())
    throw Error(where + "needs one material per triangle");
  if (!mesh.normals.empty() && mesh.normals.size() != mesh.positions.size())
    throw Error(where + "needs one normal per vertex or none");
  if (!mesh.texcoords.empty() && mesh.texcoords.size() != mesh.positions.size())
    throw Error(where + "needs one texture coordinate per vertex or none");
  for (const Eigen::Vector2f& uv : mesh.texcoords)
    if (!uv.allFinite()) throw Error(where + "has a non-finite texture coordinate");
  for (const Eigen::Vector3f& p : mesh.positions)
    if (!p.allFinite()) throw Error(where + "has a non-finite vertex position");
  for (const auto& triangle : mesh.triangles)
    for (std::uint32_t v : triangle)
      if (v >= mesh.positions.size()) throw Error(where + "refers to a missing vertex");
  for (std::uint32_t m : mesh.triangle_material)
    if (m >= material_count) throw Error(where + "refers to a missing material");
}

}  // namespace

void MrScene::validate() const {
  for (const TriangleMesh& mesh : meshes) validate_mesh(mesh, materials.size());
  for (const TriangleMesh& coarse : coarse_real_meshes) {
    validate_mesh(coarse, materials.size());
    if (!coarse.real) throw Error("coarse mesh '" + coarse.name + "' is virtual: only real meshes have coarse copies");
  }
  for (const PhongMaterial& material : materials)
    if (!material.kd.allFinite() || !std::isfinite(material.ks) || !std::isfinite(material.n) || material.n < 0.f ||
        !material.emission.allFinite())
      throw Error("material '" + material.name + "' has invalid Phong parameters");
  for (const PhongMaterial& material : materials)
    if (const std::optional<std::string> problem = specular_problem(material)) throw Error(*problem);
  for (const MrLight& light : lights)
    if (light.through_vpl && light.kind != LightKind::Directional)
      throw Error("only directional (environment) lights can reach the scene through VPLs");
}

MrScene coarse_scene(const MrScene& scene) {
  MrScene out{scene.materials, {}, scene.lights, scene.environment, {}};
  for (const TriangleMesh& mesh : scene.meshes)
    if (!mesh.real || scene.coarse_real_meshes.empty()) out.meshes.push_back(mesh);
  out.meshes.insert(out.meshes.end(), scene.coarse_real_meshes.begin(), scene.coarse_real_meshes.end());
  return out;
}

BoundingSphere bounding_sphere(const MrScene& scene, SceneMeshes meshes) {
  Eigen::AlignedBox3f box;
  for (const TriangleMesh& mesh : scene.meshes) {
    if (meshes == SceneMeshes::Virtual && mesh.real) continue;
    if (meshes == SceneMeshes::Specular) {
      for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
        if (scene.materials[mesh.triangle_material[t]].specular.specular())
          for (const std::uint32_t v : mesh.triangles[t]) box.extend(mesh.positions[v]);
      continue;
    }
    for (const Eigen::Vector3f& p : mesh.positions) box.extend(p);
  }
  BoundingSphere sphere;
  if (box.isEmpty()) return sphere;
  sphere.centre = box.center();
  sphere.radius = 0.5f * box.diagonal().norm() * 1.01f + 1e-3f;
  return sphere;
}

}  // namespace relight::render
