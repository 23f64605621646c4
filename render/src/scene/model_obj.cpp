// OBJ/MTL reading (tinyobjloader) and writing.
#include <tiny_obj_loader.h>

#include <iomanip>
#include <map>
#include <sstream>

#include "relight/core/atomic_file.h"
#include "relight/core/error.h"
#include "relight/render/scene/model_io.h"

namespace relight::render {
namespace {

PhongMaterial from_mtl(const tinyobj::material_t& m) {
  PhongMaterial out;
  out.name = m.name;
  out.kd = {m.diffuse[0], m.diffuse[1], m.diffuse[2]};
  out.ks = (m.specular[0] + m.specular[1] + m.specular[2]) / 3.f;
  out.n = std::max(1.f, m.shininess);
  out.emission = {m.emission[0], m.emission[1], m.emission[2]};
  return out;
}

/// One OBJ shape as a mesh; OBJ indexes positions and normals separately, so every distinct
/// (position, normal) pair becomes one vertex.
/// A face index (1-based in the file) past the end of its list is an error naming it: tinyobjloader
/// passes such indices through.
void check_index(const std::filesystem::path& path, int index, std::size_t available, const char* what) {
  if (index < 0 || static_cast<std::size_t>(index) >= available) {
    throw Error(path.string() + ": a face refers to " + what + " " + std::to_string(index + 1) + ", but the file has " +
                std::to_string(available));
  }
}

TriangleMesh mesh_from_shape(const std::filesystem::path& path, const tinyobj::shape_t& shape,
                             const tinyobj::attrib_t& attrib, std::uint32_t default_material) {
  TriangleMesh mesh;
  mesh.name = shape.name;
  std::map<std::pair<int, int>, std::uint32_t> vertex_of;
  bool all_normals = true;
  const auto vertex = [&](const tinyobj::index_t& index) {
    const auto key = std::pair{index.vertex_index, index.normal_index};
    if (const auto found = vertex_of.find(key); found != vertex_of.end()) return found->second;
    check_index(path, index.vertex_index, attrib.vertices.size() / 3, "vertex");
    if (index.normal_index >= 0) check_index(path, index.normal_index, attrib.normals.size() / 3, "normal");
    const auto v = static_cast<std::size_t>(index.vertex_index);
    mesh.positions.emplace_back(attrib.vertices[3 * v], attrib.vertices[3 * v + 1], attrib.vertices[3 * v + 2]);
    if (index.normal_index >= 0) {
      const auto n = static_cast<std::size_t>(index.normal_index);
      mesh.normals.emplace_back(attrib.normals[3 * n], attrib.normals[3 * n + 1], attrib.normals[3 * n + 2]);
    } else {
      all_normals = false;
    }
    const auto id = static_cast<std::uint32_t>(mesh.positions.size() - 1);
    vertex_of.emplace(key, id);
    return id;
  };
  const auto& indices = shape.mesh.indices;
  for (std::size_t face = 0; face < shape.mesh.num_face_vertices.size(); ++face) {
    const std::uint32_t a = vertex(indices[3 * face]);
    const std::uint32_t b = vertex(indices[3 * face + 1]);
    const std::uint32_t c = vertex(indices[3 * face + 2]);
    mesh.triangles.push_back({a, b, c});
    const int material = shape.mesh.material_ids[face];
    mesh.triangle_material.push_back(material >= 0 ? static_cast<std::uint32_t>(material) : default_material);
  }
  if (!all_normals) compute_vertex_normals(mesh);
  return mesh;
}

}  // namespace

VirtualModel load_obj(const std::filesystem::path& path) {
  tinyobj::ObjReaderConfig config;
  config.triangulate = true;
  config.vertex_color = false;
  config.mtl_search_path = path.parent_path().string();
  tinyobj::ObjReader reader;
  if (!reader.ParseFromFile(path.string(), config)) {
    std::string why = reader.Error();
    while (!why.empty() && (why.back() == '\n' || why.back() == '\r')) why.pop_back();
    throw Error(path.string() + ": cannot read OBJ: " + (why.empty() ? "unknown error" : why.substr(0, why.find('\n'))));
  }
  VirtualModel model;
  model.name = path.stem().string();
  for (const tinyobj::material_t& m : reader.GetMaterials()) model.materials.push_back(from_mtl(m));
  const auto default_material = static_cast<std::uint32_t>(model.materials.size());
  model.materials.push_back(PhongMaterial{{{0.7f, 0.7f, 0.7f}, 0.f, 1.f}, "default", {0.f, 0.f, 0.f}});
  const tinyobj::attrib_t& attrib = reader.GetAttrib();
  for (const tinyobj::shape_t& shape : reader.GetShapes()) {
    TriangleMesh mesh = mesh_from_shape(path, shape, attrib, default_material);
    if (!mesh.triangles.empty()) model.meshes.push_back(std::move(mesh));
  }
  if (model.meshes.empty()) throw Error(path.string() + ": the OBJ file holds no triangles");
  check_model(model, path);
  return model;
}

void save_obj(const std::filesystem::path& path, const VirtualModel& model) {
  std::filesystem::path mtl_path = path;
  mtl_path.replace_extension(".mtl");
  std::ostringstream mtl;
  mtl << std::setprecision(7) << "# written by relight\n";
  for (const PhongMaterial& m : model.materials) {
    mtl << "newmtl " << m.name << "\nKd " << m.kd.x() << ' ' << m.kd.y() << ' ' << m.kd.z() << "\nKs " << m.ks << ' '
        << m.ks << ' ' << m.ks << "\nNs " << m.n << "\nKe " << m.emission.x() << ' ' << m.emission.y() << ' '
        << m.emission.z() << "\nillum 2\n\n";
  }
  std::ostringstream obj;
  obj << std::setprecision(7) << "# written by relight: y-up, metres\nmtllib " << mtl_path.filename().string() << '\n';
  std::size_t base = 1, normal_base = 1;
  for (const TriangleMesh& mesh : model.meshes) {
    obj << "o " << (mesh.name.empty() ? "mesh" : mesh.name) << '\n';
    for (const Eigen::Vector3f& p : mesh.positions) obj << "v " << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
    for (const Eigen::Vector3f& n : mesh.normals) obj << "vn " << n.x() << ' ' << n.y() << ' ' << n.z() << '\n';
    std::uint32_t current = std::numeric_limits<std::uint32_t>::max();
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
      if (mesh.triangle_material[t] != current) {
        current = mesh.triangle_material[t];
        obj << "usemtl " << model.materials.at(current).name << '\n';
      }
      obj << 'f';
      for (std::uint32_t v : mesh.triangles[t]) {
        obj << ' ' << base + v;
        if (!mesh.normals.empty()) obj << "//" << normal_base + v;
      }
      obj << '\n';
    }
    base += mesh.positions.size();
    normal_base += mesh.normals.size();
  }
  write_file_atomically(mtl_path, mtl.str());
  write_file_atomically(path, obj.str());
}

}  // namespace relight::render
