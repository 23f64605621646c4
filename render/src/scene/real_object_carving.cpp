#include "relight/render/scene/real_object_carving.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>

namespace relight::render {
namespace {

using Vec3 = Eigen::Vector3f;

/// The point of triangle abc nearest p (Ericson, Real-Time Collision Detection §5.1.5).
Vec3 closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const float d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.f && d2 <= 0.f) return a;
  const Vec3 bp = p - b;
  const float d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.f && d4 <= d3) return b;
  const float vc = d1 * d4 - d3 * d2;
  if (vc <= 0.f && d1 >= 0.f && d3 <= 0.f) return a + d1 / (d1 - d3) * ab;
  const Vec3 cp = p - c;
  const float d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.f && d5 <= d6) return c;
  const float vb = d5 * d2 - d1 * d6;
  if (vb <= 0.f && d2 >= 0.f && d6 <= 0.f) return a + d2 / (d2 - d6) * ac;
  const float va = d3 * d6 - d5 * d4;
  if (va <= 0.f && d4 - d3 >= 0.f && d5 - d6 >= 0.f) return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
  const float denominator = 1.f / (va + vb + vc);
  return a + ab * (vb * denominator) + ac * (vc * denominator);
}

/// Whether the ray p + t d (t > 0) crosses triangle abc (Moeller-Trumbore).
bool crosses(const Vec3& p, const Vec3& d, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 e1 = b - a, e2 = c - a, h = d.cross(e2);
  const float det = e1.dot(h);
  if (std::abs(det) < 1e-12f) return false;
  const float inv = 1.f / det;
  const Vec3 s = p - a;
  const float u = inv * s.dot(h);
  if (u < 0.f || u > 1.f) return false;
  const Vec3 q = s.cross(e1);
  const float v = inv * d.dot(q);
  if (v < 0.f || u + v > 1.f) return false;
  return inv * e2.dot(q) > 0.f;
}

}  // namespace

std::size_t remove_triangles_within(TriangleMesh& mesh, std::span<const TriangleMesh> object, float margin) {
  Eigen::AlignedBox3f box;
  for (const TriangleMesh& part : object)
    for (const Vec3& p : part.positions) box.extend(p);
  if (box.isEmpty()) return 0;
  box.min().array() -= margin;
  box.max().array() += margin;
  // A direction no axis-aligned face of a model lies along, so that the parity count does not
  // graze an edge of a box-like model.
  const Vec3 ray = Vec3(0.267f, 0.534f, 0.802f).normalized();
  const auto removed = [&](const Vec3& centre) {
    if (!box.contains(centre)) return false;
    int crossings = 0;
    for (const TriangleMesh& part : object)
      for (const auto& [i, j, k] : part.triangles) {
        const Vec3 &a = part.positions[i], &b = part.positions[j], &c = part.positions[k];
        if ((closest_on_triangle(centre, a, b, c) - centre).squaredNorm() <= margin * margin) return true;
        crossings += crosses(centre, ray, a, b, c) ? 1 : 0;
      }
    return crossings % 2 == 1;
  };
  std::size_t kept = 0;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& [i, j, k] = mesh.triangles[t];
    if (removed((mesh.positions[i] + mesh.positions[j] + mesh.positions[k]) / 3.f)) continue;
    mesh.triangles[kept] = mesh.triangles[t];
    if (!mesh.triangle_material.empty()) mesh.triangle_material[kept] = mesh.triangle_material[t];
    ++kept;
  }
  const std::size_t count = mesh.triangles.size() - kept;
  mesh.triangles.resize(kept);
  if (!mesh.triangle_material.empty()) mesh.triangle_material.resize(kept);
  return count;
}

}  // namespace relight::render
