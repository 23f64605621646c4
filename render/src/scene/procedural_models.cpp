#include "relight/render/scene/procedural_models.h"

#include <cmath>
#include <numbers>

#include "relight/core/error.h"
#include "relight/render/scene/tessellation.h"

namespace relight::render {

namespace {

/// Radius of the pebble in direction (theta from +y, phi around y).
double pebble_radius(double theta, double phi) {
  const double s = std::sin(theta);
  return 0.075 * (1.0 + 0.10 * std::sin(3.0 * phi) * s * s + 0.06 * std::cos(2.0 * theta));
}

}  // namespace

VirtualModel make_glossy_pebble(int segments) {
  if (segments < 8) throw Error("the pebble needs at least 8 segments");
  VirtualModel model;
  model.name = "glossy_pebble";
  model.materials.push_back({{{0.55f, 0.08f, 0.06f}, 0.35f, 60.f}, "glossy_red", {0.f, 0.f, 0.f}});
  TriangleMesh mesh;
  mesh.name = "pebble";
  const int rings = segments / 2;
  const auto point = [](double theta, double phi) {
    const double r = pebble_radius(theta, phi);
    // Flattened vertically (0.8) so that it rests like a pebble.
    return Eigen::Vector3f(static_cast<float>(r * std::sin(theta) * std::cos(phi)),
                           static_cast<float>(0.8 * r * std::cos(theta)),
                           static_cast<float>(r * std::sin(theta) * std::sin(phi)));
  };
  // One vertex per pole and no duplicated seam column, so that the area-weighted normals are
  // smooth everywhere.
  mesh.positions.push_back(point(0.0, 0.0));
  for (int ring = 1; ring < rings; ++ring)
    for (int segment = 0; segment < segments; ++segment)
      mesh.positions.push_back(point(std::numbers::pi * ring / rings, 2.0 * std::numbers::pi * segment / segments));
  mesh.positions.push_back(point(std::numbers::pi, 0.0));
  float lowest = 0.f;
  for (const Eigen::Vector3f& p : mesh.positions) lowest = std::min(lowest, p.y());
  for (Eigen::Vector3f& p : mesh.positions) p.y() -= lowest;  // base on y = 0

  const auto top = 0u;
  const auto bottom = static_cast<std::uint32_t>(mesh.positions.size() - 1);
  const auto index = [segments](int ring, int segment) {
    return static_cast<std::uint32_t>(1 + (ring - 1) * segments + segment % segments);
  };
  for (int segment = 0; segment < segments; ++segment) {
    mesh.triangles.push_back({top, index(1, segment + 1), index(1, segment)});
    mesh.triangles.push_back({bottom, index(rings - 1, segment), index(rings - 1, segment + 1)});
    for (int ring = 1; ring < rings - 1; ++ring) {
      mesh.triangles.push_back({index(ring, segment), index(ring, segment + 1), index(ring + 1, segment)});
      mesh.triangles.push_back({index(ring, segment + 1), index(ring + 1, segment + 1), index(ring + 1, segment)});
    }
  }
  mesh.triangle_material.assign(mesh.triangles.size(), 0);
  compute_vertex_normals(mesh);
  model.meshes.push_back(std::move(mesh));
  return model;
}

VirtualModel make_matte_box() {
  VirtualModel model;
  model.name = "matte_box";
  model.materials.push_back({{{0.20f, 0.35f, 0.60f}, 0.f, 1.f}, "matte_blue", {0.f, 0.f, 0.f}});
  TriangleMesh mesh = tessellate_box({-0.06f, 0.0f, -0.06f}, {0.06f, 0.12f, 0.06f}, 0);
  mesh.name = "box";
  model.meshes.push_back(std::move(mesh));
  return model;
}

}  // namespace relight::render
