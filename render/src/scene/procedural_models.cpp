#include "relight/render/scene/procedural_models.h"

#include <cmath>
#include <numbers>
#include <vector>

#include "relight/core/error.h"
#include "relight/render/scene/tessellation.h"

namespace relight::render {

namespace {

/// Radius of the pebble in direction (theta from +y, phi around y).
double pebble_radius(double theta, double phi) {
  const double s = std::sin(theta);
  return 0.075 * (1.0 + 0.10 * std::sin(3.0 * phi) * s * s + 0.06 * std::cos(2.0 * theta));
}

/// The pebble's closed, smooth mesh (material 0, triangles wound outwards).
TriangleMesh pebble_mesh(int segments) {
  if (segments < 8) throw Error("the pebble needs at least 8 segments");
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
  return mesh;
}

/// A closed surface of revolution around +y through the profile points (radius, height), bottom
/// to top, each end closed by a fan to the axis (triangles wound outwards, material 0).
TriangleMesh lathe_mesh(const std::vector<Eigen::Vector2f>& profile, int segments) {
  TriangleMesh mesh;
  const auto rings = static_cast<int>(profile.size());
  mesh.positions.emplace_back(0.f, profile.front().y(), 0.f);
  for (const Eigen::Vector2f& p : profile)
    for (int segment = 0; segment < segments; ++segment) {
      const double phi = 2.0 * std::numbers::pi * segment / segments;
      mesh.positions.emplace_back(static_cast<float>(p.x() * std::cos(phi)), p.y(),
                                  static_cast<float>(p.x() * std::sin(phi)));
    }
  mesh.positions.emplace_back(0.f, profile.back().y(), 0.f);
  const auto bottom = 0u;
  const auto top = static_cast<std::uint32_t>(mesh.positions.size() - 1);
  const auto index = [segments](int ring, int segment) {
    return static_cast<std::uint32_t>(1 + ring * segments + segment % segments);
  };
  for (int segment = 0; segment < segments; ++segment) {
    mesh.triangles.push_back({bottom, index(0, segment), index(0, segment + 1)});
    mesh.triangles.push_back({top, index(rings - 1, segment + 1), index(rings - 1, segment)});
    for (int ring = 0; ring + 1 < rings; ++ring) {
      mesh.triangles.push_back({index(ring, segment), index(ring + 1, segment), index(ring, segment + 1)});
      mesh.triangles.push_back({index(ring, segment + 1), index(ring + 1, segment), index(ring + 1, segment + 1)});
    }
  }
  mesh.triangle_material.assign(mesh.triangles.size(), 0);
  compute_vertex_normals(mesh);
  return mesh;
}

}  // namespace

VirtualModel make_glossy_pebble(int segments) {
  VirtualModel model;
  model.name = "glossy_pebble";
  model.materials.push_back({{{0.55f, 0.08f, 0.06f}, 0.35f, 60.f}, "glossy_red", {0.f, 0.f, 0.f}});
  TriangleMesh mesh = pebble_mesh(segments);
  mesh.name = "pebble";
  model.meshes.push_back(std::move(mesh));
  return model;
}

VirtualModel make_glass_pebble(int segments) {
  VirtualModel model;
  model.name = "glass_pebble";
  PhongMaterial glass{{{0.f, 0.f, 0.f}, 0.04f, 10000.f}, "green_glass", {0.f, 0.f, 0.f}};
  glass.specular = dielectric(1.5f, {0.80f, 0.95f, 0.85f}, 0.1f);
  model.materials.push_back(glass);
  TriangleMesh mesh = pebble_mesh(segments);
  mesh.name = "pebble";
  model.meshes.push_back(std::move(mesh));
  return model;
}

VirtualModel make_metal_bottle(int segments) {
  if (segments < 8) throw Error("the bottle needs at least 8 segments");
  VirtualModel model;
  model.name = "metal_bottle";
  // Polished aluminium: F0 of about 0.91 (Schlick's colour, as PBR material tables give it).
  const Eigen::Vector3f aluminium(0.91f, 0.92f, 0.92f);
  PhongMaterial metal{{{0.f, 0.f, 0.f}, 0.91f, 10000.f}, "polished_aluminium", {0.f, 0.f, 0.f}};
  metal.specular = conductor(aluminium);
  model.materials.push_back(metal);
  // Body, rounded shoulder, neck and lip (radius, height in metres).
  const std::vector<Eigen::Vector2f> profile{{0.030f, 0.000f}, {0.034f, 0.004f}, {0.035f, 0.012f}, {0.035f, 0.110f},
                                             {0.033f, 0.125f}, {0.027f, 0.140f}, {0.018f, 0.152f}, {0.012f, 0.160f},
                                             {0.011f, 0.190f}, {0.013f, 0.193f}, {0.013f, 0.200f}, {0.009f, 0.202f}};
  TriangleMesh mesh = lathe_mesh(profile, segments);
  mesh.name = "bottle";
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
