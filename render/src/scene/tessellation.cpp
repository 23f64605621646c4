#include "relight/render/scene/tessellation.h"

#include <cmath>
#include <numbers>

#include "relight/core/error.h"

namespace relight::render {
namespace {

using Vec3 = Eigen::Vector3f;


class MeshBuilder {
 public:
  explicit MeshBuilder(std::uint32_t material) : material_(material) {}

  std::uint32_t vertex(const Vec3& position, const Vec3& normal) {
    mesh_.positions.push_back(position);
    mesh_.normals.push_back(normal.normalized());
    return static_cast<std::uint32_t>(mesh_.positions.size() - 1);
  }
  void triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    mesh_.triangles.push_back({a, b, c});
    mesh_.triangle_material.push_back(material_);
  }
  /// Quad a-b-c-d in counter-clockwise order seen from the side its normals face.
  void quad(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d) {
    triangle(a, b, c);
    triangle(a, c, d);
  }
  /// A flat rectangle: centre, half-axes u and v, normal n = u x v direction.
  void flat_rect(const Vec3& centre, const Vec3& half_u, const Vec3& half_v) {
    const Vec3 normal = half_u.cross(half_v);
    const std::uint32_t a = vertex(centre - half_u - half_v, normal);
    const std::uint32_t b = vertex(centre + half_u - half_v, normal);
    const std::uint32_t c = vertex(centre + half_u + half_v, normal);
    const std::uint32_t d = vertex(centre - half_u + half_v, normal);
    quad(a, b, c, d);
  }
  TriangleMesh take() { return std::move(mesh_); }

 private:
  std::uint32_t material_;
  TriangleMesh mesh_;
};

void check_segments(const TessellationOptions& options) {
  if (options.segments < 3) throw Error("tessellation needs at least 3 segments");
}

}  // namespace

TriangleMesh tessellate_sphere(const Vec3& centre, float radius, std::uint32_t material,
                               const TessellationOptions& options) {
  check_segments(options);
  const int segments = options.segments;
  MeshBuilder builder(material);
  const int rings = std::max(2, segments / 2);
  for (int ring = 0; ring <= rings; ++ring) {
    const double theta = std::numbers::pi * ring / rings;
    for (int segment = 0; segment <= segments; ++segment) {
      const double phi = 2.0 * std::numbers::pi * segment / segments;
      const Vec3 direction(static_cast<float>(std::sin(theta) * std::cos(phi)),
                           static_cast<float>(std::sin(theta) * std::sin(phi)), static_cast<float>(std::cos(theta)));
      builder.vertex(centre + radius * direction, direction);
    }
  }
  const auto index = [segments](int ring, int segment) {
    return static_cast<std::uint32_t>(ring * (segments + 1) + segment);
  };
  for (int ring = 0; ring < rings; ++ring)
    for (int segment = 0; segment < segments; ++segment)
      builder.quad(index(ring, segment), index(ring + 1, segment), index(ring + 1, segment + 1),
                   index(ring, segment + 1));
  return builder.take();
}

TriangleMesh tessellate_box(const Vec3& lo, const Vec3& hi, std::uint32_t material) {
  MeshBuilder builder(material);
  const Vec3 centre = 0.5f * (lo + hi);
  const Vec3 half = 0.5f * (hi - lo);
  const Vec3 x(half.x(), 0, 0), y(0, half.y(), 0), z(0, 0, half.z());
  builder.flat_rect(centre + x, y, z);
  builder.flat_rect(centre - x, z, y);
  builder.flat_rect(centre + y, z, x);
  builder.flat_rect(centre - y, x, z);
  builder.flat_rect(centre + z, x, y);
  builder.flat_rect(centre - z, y, x);
  return builder.take();
}

TriangleMesh tessellate_rectangle(const Vec3& centre, const Vec3& normal, const Vec3& half_u, const Vec3& half_v,
                                  std::uint32_t material) {
  MeshBuilder builder(material);
  // Orient the winding so that the vertex normals (u x v) equal the rectangle's normal.
  const Vec3 u = half_u.cross(half_v).dot(normal) < 0.f ? Vec3(-half_u) : half_u;
  builder.flat_rect(centre, u, half_v);
  return builder.take();
}

TriangleMesh tessellate_z_cylinder(const Vec3& base, float radius, float height, std::uint32_t material,
                                   const TessellationOptions& options) {
  check_segments(options);
  const int segments = options.segments;
  MeshBuilder builder(material);
  const Vec3 up(0, 0, height);
  std::vector<Vec3> rim;
  for (int segment = 0; segment < segments; ++segment) {
    const double phi = 2.0 * std::numbers::pi * segment / segments;
    rim.emplace_back(static_cast<float>(std::cos(phi)), static_cast<float>(std::sin(phi)), 0.f);
  }
  const auto n = static_cast<std::uint32_t>(segments);
  const std::uint32_t first_side = builder.vertex(base + radius * rim[0], rim[0]);
  builder.vertex(base + up + radius * rim[0], rim[0]);
  for (std::uint32_t s = 1; s < n; ++s) {
    builder.vertex(base + radius * rim[s], rim[s]);
    builder.vertex(base + up + radius * rim[s], rim[s]);
  }
  for (std::uint32_t s = 0; s < n; ++s) {
    const std::uint32_t next = (s + 1) % n;
    builder.quad(first_side + 2 * s, first_side + 2 * next, first_side + 2 * next + 1, first_side + 2 * s + 1);
  }
  for (const bool top : {false, true}) {
    const Vec3 normal(0, 0, top ? 1.f : -1.f);
    const Vec3 centre = top ? Vec3(base + up) : base;
    const std::uint32_t middle = builder.vertex(centre, normal);
    for (std::uint32_t s = 0; s < n; ++s) builder.vertex(centre + radius * rim[s], normal);
    for (std::uint32_t s = 0; s < n; ++s) {
      const std::uint32_t a = middle + 1 + s;
      const std::uint32_t b = middle + 1 + (s + 1) % n;
      if (top)
        builder.triangle(middle, a, b);
      else
        builder.triangle(middle, b, a);
    }
  }
  return builder.take();
}

}  // namespace relight::render
