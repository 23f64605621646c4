#include "relight/render/scene/depth_mesh.h"

#include <algorithm>

#include "relight/core/error.h"

namespace relight::render {
namespace {

bool valid_position(const Float3& p) { return p.z > 0.f && std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z); }

Eigen::Vector3f vec(const Float3& p) { return {p.x, p.y, p.z}; }

/// Builds the grid: vertex ids per grid point (or -1), then triangles that pass the edge test.
class GridMesher {
 public:
  GridMesher(const PositionMap& positions, const NormalMap* normals, const Pose& camera_to_world,
             const DepthMeshMaterials& materials, const DepthMeshOptions& options)
      : positions_(positions), normals_(normals), materials_(materials), options_(options) {
    const Eigen::Isometry3f pose = camera_to_world.cast<float>();
    cols_ = (positions.width() - 1) / options.stride + 1;
    rows_ = (positions.height() - 1) / options.stride + 1;
    vertex_.assign(static_cast<std::size_t>(cols_) * static_cast<std::size_t>(rows_), -1);
    for (int r = 0; r < rows_; ++r)
      for (int c = 0; c < cols_; ++c) add_vertex(r, c, pose);
  }

  TriangleMesh take() {
    for (int r = 0; r + 1 < rows_; ++r)
      for (int c = 0; c + 1 < cols_; ++c) {
        add_triangle(r, c, r + 1, c, r, c + 1);
        add_triangle(r, c + 1, r + 1, c, r + 1, c + 1);
      }
    if (mesh_.normals.size() != mesh_.positions.size()) mesh_.normals.clear();
    mesh_.name = "reconstruction";
    mesh_.real = true;
    return std::move(mesh_);
  }

 private:
  void add_vertex(int r, int c, const Eigen::Isometry3f& pose) {
    const Float3 p = positions_(r * options_.stride, c * options_.stride);
    if (!valid_position(p)) return;
    vertex_[index(r, c)] = static_cast<std::int64_t>(mesh_.positions.size());
    mesh_.positions.push_back(pose * vec(p));
    depth_.push_back(p.z);
    if (normals_ != nullptr) {
      const Float3 n = (*normals_)(r * options_.stride, c * options_.stride);
      mesh_.normals.push_back(is_valid_normal(n) ? Eigen::Vector3f(pose.linear() * vec(n).normalized())
                                                 : Eigen::Vector3f(pose.linear() * Eigen::Vector3f(0, 0, -1)));
    }
  }

  void add_triangle(int r0, int c0, int r1, int c1, int r2, int c2) {
    const std::int64_t a = vertex_[index(r0, c0)], b = vertex_[index(r1, c1)], c = vertex_[index(r2, c2)];
    if (a < 0 || b < 0 || c < 0) return;
    const auto ua = static_cast<std::uint32_t>(a), ub = static_cast<std::uint32_t>(b), uc = static_cast<std::uint32_t>(c);
    const float depth = std::min({depth_[ua], depth_[ub], depth_[uc]});
    const float longest = std::max(options_.min_edge, options_.relative_edge * depth);
    const auto& p = mesh_.positions;
    if ((p[ua] - p[ub]).norm() > longest || (p[ub] - p[uc]).norm() > longest || (p[uc] - p[ua]).norm() > longest) return;
    mesh_.triangles.push_back({ua, ub, uc});
    mesh_.triangle_material.push_back(material_at(r0 * options_.stride, c0 * options_.stride));
  }

  [[nodiscard]] std::uint32_t material_at(int row, int col) const {
    if (materials_.labels == nullptr) return materials_.material;
    const std::uint16_t label = (*materials_.labels)(row, col);
    return label < materials_.material_of_label.size() ? materials_.material_of_label[label] : materials_.material;
  }

  [[nodiscard]] std::size_t index(int r, int c) const {
    return static_cast<std::size_t>(r) * static_cast<std::size_t>(cols_) + static_cast<std::size_t>(c);
  }

  const PositionMap& positions_;
  const NormalMap* normals_;
  const DepthMeshMaterials& materials_;
  const DepthMeshOptions& options_;
  int rows_ = 0, cols_ = 0;
  std::vector<std::int64_t> vertex_;
  std::vector<float> depth_;
  TriangleMesh mesh_;
};

}  // namespace

TriangleMesh mesh_from_positions(const PositionMap& positions, const NormalMap* normals, const Pose& camera_to_world,
                                 const DepthMeshMaterials& materials, const DepthMeshOptions& options) {
  if (options.stride < 1) throw Error("depth mesh stride must be at least 1");
  if (!(options.relative_edge > 0.f)) throw Error("depth mesh relative edge must be positive");
  if (normals != nullptr && (normals->width() != positions.width() || normals->height() != positions.height()))
    throw Error("depth mesh: the normal map and the position map differ in size");
  if (materials.labels != nullptr &&
      (materials.labels->width() != positions.width() || materials.labels->height() != positions.height()))
    throw Error("depth mesh: the label image and the position map differ in size");
  if (positions.width() < 2 || positions.height() < 2) return TriangleMesh{};
  return GridMesher(positions, normals, camera_to_world, materials, options).take();
}

PositionMap positions_from_depth(const DepthMap& depth, const PinholeIntrinsics& intrinsics) {
  PositionMap out(depth.width(), depth.height());
  for (int row = 0; row < depth.height(); ++row)
    for (int col = 0; col < depth.width(); ++col) {
      const float z = depth(row, col);
      if (!is_valid_depth(z)) continue;
      const Eigen::Vector3d p = intrinsics.unproject(col, row, z);
      out(row, col) = {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())};
    }
  return out;
}

}  // namespace relight::render
