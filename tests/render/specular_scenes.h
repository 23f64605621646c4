#pragma once
// Pieces of the scenes with mirrors and glass that the path tracer's and DIR's specular tests
// share (specular_material.h).
#include <optional>

#include "relight/core/image.h"
#include "relight/render/reference/ray_tracer.h"
#include "relight/render/scene/mr_scene.h"
#include "test_scenes.h"

namespace relight::render::test {

inline PhongMaterial specular_material(const SpecularMaterial& specular, const char* name) {
  PhongMaterial m;
  m.name = name;
  m.kd = Eigen::Vector3f::Zero();
  m.specular = specular;
  return m;
}

inline PhongMaterial emitter(float radiance) {
  PhongMaterial m = diffuse(Eigen::Vector3f::Zero(), "emitter");
  m.emission = Eigen::Vector3f::Constant(radiance);
  return m;
}

inline TriangleMesh with_layer(TriangleMesh mesh, const char* name, bool real) {
  mesh.name = name;
  mesh.real = real;
  return mesh;
}

inline Eigen::Vector3f at(const RadianceImage& image, int row, int col) {
  const Float3 p = image(row, col);
  return {p.x, p.y, p.z};
}

/// The first hit of a pixel centre's ray in `layer`.
inline std::optional<SurfaceHit> pixel_hit(const RayTracer& tracer, const MrCamera& camera, int row, int col,
                                           Layer layer) {
  const Eigen::Vector3d d = camera.camera_to_world.linear() * camera.intrinsics.ray(col, row).normalized();
  return tracer.intersect(layer, camera.camera_to_world.translation().cast<float>(), d.cast<float>());
}

}  // namespace relight::render::test
