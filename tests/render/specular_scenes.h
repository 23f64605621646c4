#pragma once
// Pieces of the scenes with mirrors and glass that the path tracer's and DIR's specular tests
// share (specular_material.h).
#include <optional>
#include <utility>
#include <vector>

#include "relight/core/image.h"
#include "relight/render/differential_images.h"
#include "relight/render/reference/ray_tracer.h"
#include "relight/render/scene/mr_scene.h"
#include "relight/render/scene/tessellation.h"
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

/// Transmittance of a clear-walled slab at normal incidence with internal reflections: light
/// crosses two interfaces of reflectance R and the absorbing inside (a per pass) any odd number
/// of times, (1 - R)^2 a / (1 - R^2 a^2).
inline float slab_transmittance(float ior, float a) {
  const float r = (ior - 1.f) * (ior - 1.f) / ((ior + 1.f) * (ior + 1.f));
  return (1.f - r) * (1.f - r) * a / (1.f - r * r * a * a);
}

/// floor_scene lit by a sun straight above (irradiance `sun`) through a virtual glass slab
/// 1 m wide, 10 cm thick, 0.5 m above the floor, of IOR 1.5 and attenuation `colour` per 10 cm.
inline MrScene sunlit_glass_slab(float sun, float albedo, const Eigen::Vector3f& colour) {
  MrScene scene = floor_scene(Eigen::Vector3f::Constant(albedo), {0, 0, 1}, 0.f);
  scene.lights[0].kind = LightKind::Directional;
  scene.lights[0].direction = Eigen::Vector3f::UnitZ();
  scene.lights[0].intensity = Eigen::Vector3f::Constant(sun);
  scene.meshes.push_back(
      with_layer(tessellate_box({-0.5f, -0.5f, 0.5f}, {0.5f, 0.5f, 0.6f},
                                scene.add_material(specular_material(dielectric(1.5f, colour, 0.1f), "glass"))),
                 "slab", false));
  return scene;
}

/// Expects the mean of L_rv over `under` (floor pixels below the slab) to be `lit` times the
/// slab's transmittance per channel (within `tolerance`, relative) and that of L_r `lit` (the
/// slab is virtual: L_r has the sun alone, within `real_tolerance`).
inline void expect_sun_through_slab(const DifferentialImages& images, const std::vector<std::pair<int, int>>& under,
                                    double lit, const Eigen::Vector3f& colour, double tolerance,
                                    double real_tolerance) {
  const Eigen::Vector3d through = mean_over(images.real_virtual, under), real = mean_over(images.real, under);
  for (int c = 0; c < 3; ++c) {
    const double expected = lit * slab_transmittance(1.5f, colour[c]);
    EXPECT_NEAR(through[c], expected, tolerance * expected) << "channel " << c;
    EXPECT_NEAR(real[c], lit, real_tolerance * lit) << "channel " << c;
  }
}

}  // namespace relight::render::test
