#pragma once
// Small analytic mixed-reality scenes with known answers for the renderer tests.
#include <gtest/gtest.h>

#include <algorithm>
#include <utility>
#include <vector>

#include "relight/core/image.h"
#include "relight/render/scene/mr_scene.h"
#include "relight/render/reference/path_tracer.h"
#include "relight/render/scene/procedural_models.h"
#include "relight/render/reference/ray_tracer.h"
#include "relight/truth/scene_from_synth.h"
#include "relight/render/scene/virtual_model.h"
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
  TriangleMesh floor = truth::tessellate(synth::Rect{{0, 0, 0}, {0, 0, 1}, {1, 0, 0}, {0, 1, 0}, 2, 2}, floor_material);
  floor.name = "floor";
  scene.meshes.push_back(floor);
  MrLight point;
  point.position = light;
  point.intensity = Eigen::Vector3f::Constant(intensity);
  scene.lights.push_back(point);
  return scene;
}

/// The synthetic room (objects tessellated with 48 segments, smooth-shaded) with the glossy
/// pebble standing on its table, and the room's own lights.
inline MrScene indoor_with_pebble() {
  MrScene scene = truth::scene_from_synth(synth::default_indoor_scene(), {48});
  add_virtual_model(scene, make_glossy_pebble(), Placement::parse("0.35,-0.2,0.75,30"));
  return scene;
}

/// Adds a virtual box with the given material.
inline void add_virtual_box(MrScene& scene, const synth::Box& box, const PhongMaterial& material) {
  TriangleMesh mesh = truth::tessellate(box, scene.add_material(material));
  mesh.name = "virtual box";
  mesh.real = false;
  scene.meshes.push_back(mesh);
}

/// A side x side texel checkerboard of cell x cell squares, colours a and b (sRGB).
inline ColorImage checkerboard(int side, int cell, Rgb8 a, Rgb8 b) {
  ColorImage out(side, side);
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x) out(y, x) = ((x / cell + y / cell) % 2 == 0) ? a : b;
  return out;
}

/// Gives every virtual mesh of `scene` texture coordinates (a planar projection, 2.5 (x + z,
/// y + z) in metres: 0.4 m per repeat) and the materials it uses a red and white checkerboard
/// of 4 x 4 cells.
inline void texture_virtual_meshes(MrScene& scene) {
  const auto texture =
      std::make_shared<const Texture>("checker", checkerboard(32, 8, Rgb8{230, 40, 30}, Rgb8{240, 240, 240}));
  for (TriangleMesh& mesh : scene.meshes) {
    if (mesh.real) continue;
    mesh.texcoords.clear();
    for (const Eigen::Vector3f& p : mesh.positions)
      mesh.texcoords.emplace_back(2.5f * (p.x() + p.z()), 2.5f * (p.y() + p.z()));
    for (const std::uint32_t m : mesh.triangle_material) scene.materials[m].base_color = texture;
  }
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

/// Relative error of the differential image ΔL = L_rv − L_r of `dir` against `reference`,
/// averaged over the real floor pixels inside [lo, hi] (at least 9 of them are expected).
inline double delta_error_on_floor(const MrScene& scene, const MrCamera& camera, const DifferentialImages& reference,
                                   const DifferentialImages& dir, const Eigen::Vector2f& lo, const Eigen::Vector2f& hi) {
  const auto pixels = floor_pixels(scene, camera, lo, hi);
  EXPECT_GT(pixels.size(), 8u);
  const Eigen::Vector3d d_ref = mean_over(reference.real_virtual, pixels) - mean_over(reference.real, pixels);
  const Eigen::Vector3d d_dir = mean_over(dir.real_virtual, pixels) - mean_over(dir.real, pixels);
  return (d_dir - d_ref).norm() / d_ref.norm();
}

/// The view of the cube scenes' floor that the path-tracer comparisons use (48 x 36).
inline MrCamera comparison_camera() { return camera_at({0.2, -1.5, 1.4}, {0, 0, 0.1}, 48, 36); }

/// The path tracer's L_rv and L_r with `bounces` indirect bounces and no Russian roulette
/// before them (256 samples per pixel): what DIR with as many bounces estimates.
inline DifferentialImages reference_images(const MrScene& scene, const MrCamera& camera, int bounces) {
  PathTracerOptions options;
  options.max_bounces = bounces;
  options.roulette_from = 10;
  return render_reference(scene, camera, 256, options);
}

/// The floor regions of the cube scenes that the virtual cube changes: its umbra (away from the
/// light) and its red bleeding (towards the light).
inline const Eigen::Vector2f kShadowLo{-0.45f, -0.12f}, kShadowHi{-0.25f, 0.12f};
inline const Eigen::Vector2f kBleedingLo{0.22f, -0.15f}, kBleedingHi{0.45f, 0.15f};

}  // namespace relight::render::test
