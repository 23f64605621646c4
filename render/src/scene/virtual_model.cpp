#include "relight/render/scene/virtual_model.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <optional>
#include <sstream>

#include "relight/core/error.h"

namespace relight::render {

Placement Placement::parse(const std::string& text) {
  std::vector<double> values;
  std::stringstream stream(text);
  std::string field;
  while (std::getline(stream, field, ',')) {
    try {
      std::size_t used = 0;
      values.push_back(std::stod(field, &used));
      if (used != field.size()) throw std::invalid_argument(field);
    } catch (const std::exception&) {
      throw Error("placement '" + text + "': '" + field + "' is not a number (expected x,y,z[,yaw_degrees[,scale]])");
    }
  }
  if (values.size() < 3 || values.size() > 5)
    throw Error("placement '" + text + "' needs 3 to 5 numbers: x,y,z[,yaw_degrees[,scale]]");
  for (double v : values)
    if (!std::isfinite(v)) throw Error("placement '" + text + "' has a non-finite number");
  Placement p;
  p.position = {values[0], values[1], values[2]};
  if (values.size() > 3) p.yaw_degrees = values[3];
  if (values.size() > 4) p.scale = values[4];
  if (!(p.scale > 0.0)) throw Error("placement '" + text + "': the scale must be positive");
  return p;
}

Eigen::Affine3d Placement::transform() const {
  Eigen::Matrix3d y_up_to_z_up;
  y_up_to_z_up << 1, 0, 0, 0, 0, -1, 0, 1, 0;
  const Eigen::AngleAxisd yaw(yaw_degrees * std::numbers::pi / 180.0, Eigen::Vector3d::UnitZ());
  Eigen::Affine3d t = Eigen::Affine3d::Identity();
  t.translate(position);
  const Eigen::Matrix3d z_to_up = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), up).toRotationMatrix();
  t.rotate(z_to_up * yaw.toRotationMatrix() * y_up_to_z_up);
  t.scale(scale);
  return t;
}

namespace {

/// Whether every edge of the mesh's triangles that use a glass material is shared by exactly two
/// of them, vertices welded by position (glTF splits vertices at texture seams).
bool glass_is_closed(const TriangleMesh& mesh, const std::vector<PhongMaterial>& materials) {
  std::map<std::array<float, 3>, std::uint32_t> welded;
  const auto id = [&](std::uint32_t v) {
    const Eigen::Vector3f& p = mesh.positions[v];
    return welded.try_emplace({p.x(), p.y(), p.z()}, static_cast<std::uint32_t>(welded.size())).first->second;
  };
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
  bool any = false;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    if (materials[mesh.triangle_material[t]].specular.kind != SpecularKind::Dielectric) continue;
    any = true;
    for (std::size_t e = 0; e < 3; ++e) {
      const std::uint32_t a = id(mesh.triangles[t][e]), b = id(mesh.triangles[t][(e + 1) % 3]);
      ++edges[{std::min(a, b), std::max(a, b)}];
    }
  }
  return !any || std::all_of(edges.begin(), edges.end(), [](const auto& edge) { return edge.second == 2; });
}

}  // namespace

void check_model(VirtualModel& model, const std::filesystem::path& file) {
  const auto fail = [&file](const TriangleMesh& mesh, const std::string& why) {
    throw Error(file.string() + ": " + (mesh.name.empty() ? "" : "mesh '" + mesh.name + "': ") + why);
  };
  for (const PhongMaterial& material : model.materials)
    if (const std::optional<std::string> problem = specular_problem(material))
      throw Error(file.string() + ": " + *problem);
  for (const TriangleMesh& mesh : model.meshes) {
    for (std::size_t v = 0; v < mesh.positions.size(); ++v)
      if (!mesh.positions[v].allFinite()) fail(mesh, "vertex " + std::to_string(v + 1) + " is not finite");
    for (std::size_t v = 0; v < mesh.normals.size(); ++v)
      if (!mesh.normals[v].allFinite()) fail(mesh, "normal " + std::to_string(v + 1) + " is not finite");
    for (std::size_t v = 0; v < mesh.texcoords.size(); ++v)
      if (!mesh.texcoords[v].allFinite()) fail(mesh, "texture coordinate " + std::to_string(v + 1) + " is not finite");
    if (!mesh.texcoords.empty() && mesh.texcoords.size() != mesh.positions.size())
      fail(mesh, std::to_string(mesh.texcoords.size()) + " texture coordinates for " +
                     std::to_string(mesh.positions.size()) + " vertices");
    if (mesh.triangle_material.size() != mesh.triangles.size()) fail(mesh, "triangles without a material");
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
      for (const std::uint32_t index : mesh.triangles[t])
        if (index >= mesh.positions.size())
          fail(mesh, "triangle " + std::to_string(t + 1) + " refers to vertex " + std::to_string(index) +
                         ", but the mesh has " + std::to_string(mesh.positions.size()));
      if (mesh.triangle_material[t] >= model.materials.size())
        fail(mesh, "triangle " + std::to_string(t + 1) + " uses material " + std::to_string(mesh.triangle_material[t]) +
                       ", but the model has " + std::to_string(model.materials.size()));
    }
    if (!glass_is_closed(mesh, model.materials))
      model.warnings.push_back((mesh.name.empty() ? "a glass mesh" : "glass mesh '" + mesh.name + "'") +
                               " is not a closed surface: rays that enter it may not leave (rendered as a thin sheet)");
  }
}

namespace {

void add_model(MrScene& scene, const VirtualModel& model, const Placement& placement, bool real) {
  const auto first_material = static_cast<std::uint32_t>(scene.materials.size());
  for (const PhongMaterial& m : model.materials) scene.materials.push_back(m);
  const Eigen::Affine3f t = placement.transform().cast<float>();
  const Eigen::Matrix3f normal_matrix = t.linear().inverse().transpose();
  for (const TriangleMesh& source : model.meshes) {
    TriangleMesh mesh = source;
    mesh.real = real;
    for (Eigen::Vector3f& p : mesh.positions) p = t * p;
    for (Eigen::Vector3f& n : mesh.normals) n = (normal_matrix * n).normalized();
    for (std::uint32_t& m : mesh.triangle_material) m += first_material;
    scene.meshes.push_back(std::move(mesh));
  }
}

}  // namespace

void add_virtual_model(MrScene& scene, const VirtualModel& model, const Placement& placement) {
  add_model(scene, model, placement, false);
}

std::span<const TriangleMesh> add_real_model(MrScene& scene, const VirtualModel& model, const Placement& placement) {
  const std::size_t first = scene.meshes.size();
  add_model(scene, model, placement, true);
  return {scene.meshes.data() + first, scene.meshes.size() - first};
}

Eigen::AlignedBox3f bounds(const VirtualModel& model) {
  Eigen::AlignedBox3f box;
  for (const TriangleMesh& mesh : model.meshes)
    for (const Eigen::Vector3f& p : mesh.positions) box.extend(p);
  return box;
}

void compute_vertex_normals(TriangleMesh& mesh) {
  mesh.normals.assign(mesh.positions.size(), Eigen::Vector3f::Zero());
  for (const auto& [a, b, c] : mesh.triangles) {
    // The unnormalised cross product weights each face by its area.
    const Eigen::Vector3f n = (mesh.positions[b] - mesh.positions[a]).cross(mesh.positions[c] - mesh.positions[a]);
    for (std::uint32_t v : {a, b, c}) mesh.normals[v] += n;
  }
  for (Eigen::Vector3f& n : mesh.normals) {
    const float length = n.norm();
    n = length > 0.f ? Eigen::Vector3f(n / length) : Eigen::Vector3f::UnitY();
  }
}

}  // namespace relight::render
