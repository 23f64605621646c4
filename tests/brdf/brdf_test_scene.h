#pragma once
// The synthetic ground truth for the BRDF tests: one 640x480 view of synth::default_indoor_scene
// from the static trajectory's pose, with the exact camera-frame positions and normals, the
// exact light set (the two point lights plus the constant environment as ambient radiance) and,
// per pixel, the split of the rendered radiance into its diffuse and specular parts and whether
// every light that faces the point reaches it (no shadow). Rendered once per test process.
#include <Eigen/Core>
#include <cmath>
#include <numbers>

#include "relight/brdf/shading.h"
#include "relight/core/image.h"
#include "relight/synth/raycast.h"
#include "relight/synth/scene.h"
#include "relight/synth/trajectory.h"

namespace relight::test {

struct BrdfScene {
  synth::Scene scene;
  PinholeIntrinsics intrinsics;
  Pose camera_to_world;
  synth::RenderedFrame truth;
  PositionMap positions;      ///< camera frame; (0,0,0) where nothing was hit
  RadianceImage diffuse;      ///< k_d * (environment + sum over lit lights E / pi)
  RadianceImage specular;     ///< radiance - diffuse (grey)
  Mask shadowed;              ///< 1 where a light facing the point is blocked
  ColorImage color;           ///< the 8-bit camera image (exposure 1)
  brdf::ShadingLights lights; ///< exact, camera frame, ambient = environment
};

inline lights::LightSet light_set_of(const synth::Scene& scene) {
  lights::LightSet set;
  for (const synth::PointLight& l : scene.lights) {
    lights::Light light;
    light.kind = lights::LightKind::Point;
    light.position = l.position;
    light.power = l.colour * l.intensity;
    set.lights.push_back(light);
  }
  return set;
}

inline BrdfScene make_brdf_scene(int width = 640, int height = 480) {
  BrdfScene s;
  s.scene = synth::default_indoor_scene();
  s.intrinsics = PinholeIntrinsics::kinect_v1();
  s.intrinsics.fx *= width / 640.0;
  s.intrinsics.fy *= width / 640.0;
  s.intrinsics.cx = (width - 1) / 2.0;
  s.intrinsics.cy = (height - 1) / 2.0;
  s.intrinsics.width = width;
  s.intrinsics.height = height;
  s.camera_to_world = synth::make_trajectory(synth::Trajectory::Static, 1, 0, s.scene)[0];
  s.truth = synth::render_frame(s.scene, s.intrinsics, s.camera_to_world);
  s.lights = brdf::to_camera_frame(light_set_of(s.scene), s.camera_to_world, s.scene.environment.cast<float>());
  s.positions = PositionMap(width, height);
  s.diffuse = RadianceImage(width, height);
  s.specular = RadianceImage(width, height);
  s.shadowed = Mask(width, height);
  for (int r = 0; r < height; ++r) {
    for (int c = 0; c < width; ++c) {
      const float z = s.truth.depth(r, c);
      if (z <= 0.f) continue;
      const Eigen::Vector3d p_cam = s.intrinsics.unproject(c, r, z);
      s.positions(r, c) = {static_cast<float>(p_cam.x()), static_cast<float>(p_cam.y()), static_cast<float>(p_cam.z())};
      const Float3 nc = s.truth.normals(r, c);
      const Eigen::Vector3d n_world = s.camera_to_world.linear() * Eigen::Vector3d(nc.x, nc.y, nc.z);
      const Eigen::Vector3d p_world = s.camera_to_world * p_cam;
      const Float3 kd = s.truth.albedo(r, c);
      Eigen::Vector3d shading = s.scene.environment;
      for (const synth::PointLight& light : s.scene.lights) {
        const Eigen::Vector3d offset = light.position - p_world;
        const double d2 = offset.squaredNorm();
        const double cosine = n_world.dot(offset / std::sqrt(d2));
        if (cosine <= 0.0) continue;
        if (synth::occluded(s.scene, p_world + 1e-6 * n_world, light.position)) {
          s.shadowed(r, c) = 1;
          continue;
        }
        shading += light.colour * (light.intensity * cosine / d2 / std::numbers::pi);
      }
      const Float3 diffuse{static_cast<float>(kd.x * shading.x()), static_cast<float>(kd.y * shading.y()),
                           static_cast<float>(kd.z * shading.z())};
      s.diffuse(r, c) = diffuse;
      s.specular(r, c) = s.truth.radiance(r, c) - diffuse;
    }
  }
  s.color = synth::encode_color(s.truth.radiance);
  return s;
}

/// The 640x480 scene, rendered on first use.
inline const BrdfScene& brdf_scene() {
  static const BrdfScene scene = make_brdf_scene();
  return scene;
}

inline int material_id(const synth::Scene& scene, const char* name) { return scene.material_index(name) + 1; }

}  // namespace relight::test
