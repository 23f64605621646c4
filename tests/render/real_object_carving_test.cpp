#include "relight/render/scene/real_object_carving.h"

#include <gtest/gtest.h>

#include <vector>

#include "relight/render/scene/tessellation.h"

namespace relight::render {
namespace {

using Eigen::Vector3f;

/// A square of half-width `half` at height z, in cells x cells squares of two triangles each.
TriangleMesh grid(float z, float half, int cells, std::uint32_t material) {
  TriangleMesh mesh;
  const float step = 2.f * half / static_cast<float>(cells);
  for (int y = 0; y <= cells; ++y)
    for (int x = 0; x <= cells; ++x)
      mesh.positions.emplace_back(-half + static_cast<float>(x) * step, -half + static_cast<float>(y) * step, z);
  const auto at = [cells](int x, int y) { return static_cast<std::uint32_t>(y * (cells + 1) + x); };
  for (int y = 0; y < cells; ++y)
    for (int x = 0; x < cells; ++x) {
      mesh.triangles.push_back({at(x, y), at(x + 1, y), at(x + 1, y + 1)});
      mesh.triangles.push_back({at(x, y), at(x + 1, y + 1), at(x, y + 1)});
    }
  mesh.triangle_material.assign(mesh.triangles.size(), material);
  return mesh;
}

/// The triangles' centres.
std::vector<Vector3f> centres(const TriangleMesh& mesh) {
  std::vector<Vector3f> out;
  for (const auto& [i, j, k] : mesh.triangles)
    out.emplace_back((mesh.positions[i] + mesh.positions[j] + mesh.positions[k]) / 3.f);
  return out;
}

// A 10 cm box standing on a finely tessellated table, and a sheet through the box's middle (the
// depth camera's noisy view of a glass): the table keeps every triangle but those under the box
// and within the margin of it; the sheet loses the triangles inside the box and near it, and
// keeps the rest. Materials stay with their triangles.
TEST(RealObjectCarving, TrianglesInsideOrNearTheObjectGoTheRestStay) {
  const float margin = 0.01f;
  const std::vector<TriangleMesh> box{tessellate_box({-0.05f, -0.05f, 0.f}, {0.05f, 0.05f, 0.1f}, 0)};
  TriangleMesh table = grid(0.f, 0.3f, 120, 7);
  TriangleMesh sheet = grid(0.05f, 0.3f, 120, 9);
  ASSERT_EQ(table.triangle_material.size(), table.triangles.size());
  const auto expected_left = [&](const TriangleMesh& mesh) {
    std::size_t left = 0;
    for (const Vector3f& c : centres(mesh)) {
      // Distance to the box in the plane (both meshes lie at the box's bottom or cross it).
      const float dx = std::max(0.f, std::abs(c.x()) - 0.05f), dy = std::max(0.f, std::abs(c.y()) - 0.05f);
      const bool near = std::hypot(dx, dy) <= margin;
      left += near ? 0 : 1;
    }
    return left;
  };
  const std::size_t table_left = expected_left(table), sheet_left = expected_left(sheet);
  const std::size_t table_before = table.triangles.size(), sheet_before = sheet.triangles.size();
  EXPECT_EQ(remove_triangles_within(table, box, margin), table_before - table_left);
  EXPECT_EQ(remove_triangles_within(sheet, box, margin), sheet_before - sheet_left);
  EXPECT_EQ(table.triangles.size(), table_left);
  EXPECT_EQ(sheet.triangles.size(), sheet_left);
  EXPECT_GT(table_before - table_left, 300u);  // the box's footprint, 10 x 10 cm of 0.5 cm cells, and the ring
  for (const Vector3f& c : centres(table)) EXPECT_FALSE(std::abs(c.x()) < 0.05f && std::abs(c.y()) < 0.05f);
  for (const std::uint32_t m : table.triangle_material) EXPECT_EQ(m, 7u);
  ASSERT_EQ(sheet.triangle_material.size(), sheet.triangles.size());
  // Nothing near a model far away is touched.
  const std::vector<TriangleMesh> far_box{tessellate_box({2.f, 2.f, 0.f}, {2.1f, 2.1f, 0.1f}, 0)};
  EXPECT_EQ(remove_triangles_within(table, far_box, margin), 0u);
}

}  // namespace
}  // namespace relight::render
