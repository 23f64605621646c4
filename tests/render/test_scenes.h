#pragma once
// Small analytic mixed-reality scenes with known answers for the renderer tests.
#include <algorithm>
#include <utility>
#include <vector>

#include "relight/core/image.h"
#include "relight/render/mr_scene.h"
#include "relight/render/ray_tracer.h"
#include "relight/render/scene_from_synth.h"
#include "relight/synth/trajectory.h"

namespace relight::render::test {

inline PhongMaterial diffuse(const Eigen::Vector3f& kd, const char* name = "diffuse") {
  PhongMaterial m;
  m.name = name;
  m.kd = kd;
  return m;
}

/// A real square floor (z = 0, 4 m wide, albedo `albedo`) lit by one real point light of
/// intensity `intensity` at `light`.
inline MrScene floor_scene(const Eigen::Vector3f& albedo, const Eigen::Vector3f& light, float intensity) {
  MrScene scene;
  const std::uint32_t floor_material = scene.add_material(diffuse(albedo, "floor"));
  TriangleMesh floor = tessellate(synth::Rect{{0, 0, 0}, {0, 0, 1}, {1, 0, 0}, {0, 1, 0}, 2, 2}, floor_material);
  floor.name = "floor";
  scene.meshes.push_back(floor);
  MrLight point;
  point.position = light;
  point.intensity = Eigen::Vector3f::Constant(intensity);
  scene.lights.push_back(point);
  return scene;
}

/// Adds a virtual box with the given material.
inline void add_virtual_box(MrScene& scene, const synth::Box& box, const PhongMaterial& material) {
  TriangleMesh mesh = tessellate(box, scene.add_material(material));
  mesh.name = "virtual box";
  mesh.real = false;
  scene.meshes.push_back(mesh);
}

/// A camera of `width` x `height` pixels (focal length scaled from the Kinect's) at `eye`
/// looking at `target`.
inline MrCamera camera_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target, int width, int height) {
  MrCamera camera;
  const double scale = width / 640.0;
  camera.intrinsics = {525.0 * scale, 525.0 * scale, (width - 1) / 2.0, (height - 1) / 2.0, width, height};
  camera.camera_to_world = synth::look_at(eye, target);
  return camera;
}

inline Eigen::Vector3d mean_over(const RadianceImage& image, const std::vector<std::pair<int, int>>& pixels) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const auto& [row, col] : pixels) sum += Eigen::Vector3d(image(row, col).x, image(row, col).y, image(row, col).z);
  return sum / static_cast<double>(std::max<std::size_t>(1, pixels.size()));
}

/// Pixels whose centre ray first meets the real floor inside the box [lo, hi] (x, y).
inline std::vector<std::pair<int, int>> floor_pixels(const MrScene& scene, const MrCamera& camera, const Eigen::Vector2f& lo,
                                              const Eigen::Vector2f& hi) {
  const RayTracer tracer(scene);
  std::vector<std::pair<int, int>> pixels;
  const Eigen::Vector3f origin = camera.camera_to_world.translation().cast<float>();
  for (int row = 0; row < camera.intrinsics.height; ++row)
    for (int col = 0; col < camera.intrinsics.width; ++col) {
      const Eigen::Vector3f d = (camera.camera_to_world.linear() * camera.intrinsics.ray(col, row).normalized()).cast<float>();
      const auto real = tracer.intersect(Layer::Real, origin, d);
      if (!real || tracer.occluded(Layer::Virtual, origin, d, real->t)) continue;
      const Eigen::Vector2f p = real->point.head<2>();
      if (std::abs(real->point.z()) < 1e-4f && (p.array() >= lo.array()).all() && (p.array() <= hi.array()).all())
        pixels.emplace_back(row, col);
    }
  return pixels;
}

}  // namespace relight::render::test
