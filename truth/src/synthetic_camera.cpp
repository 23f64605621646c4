// Synthetic camera and L_r / L_rv / L_cam triples (synthetic_camera.h).
#include "relight/truth/synthetic_camera.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "relight/colormap/ciede2000.h"
#include "relight/colormap/color_space.h"
#include "relight/core/error.h"
#include "relight/synth/raycast.h"
#include "relight/synth/trajectory.h"

namespace relight::truth {

CameraColorTransform CameraColorTransform::typical() {
  CameraColorTransform camera;
  camera.gains = {1.4, 1.0, 0.6};
  camera.crosstalk << 0.85, 0.10, 0.05,  //
      0.08, 0.84, 0.08,                  //
      0.04, 0.11, 0.85;
  camera.exposure = 0.8;
  camera.gamma = 2.2;
  return camera;
}

ColorImage apply_camera(const RadianceImage& radiance, const CameraColorTransform& camera) {
  const Eigen::Matrix3d transform = camera.exposure * camera.crosstalk * camera.gains.asDiagonal();
  std::mt19937_64 random(camera.noise_seed);
  std::normal_distribution<double> noise(0.0, camera.noise_sigma > 0.0 ? camera.noise_sigma : 1.0);
  ColorImage image(radiance.width(), radiance.height());
  for (std::size_t i = 0; i < radiance.size(); ++i) {
    const Float3& l = radiance.pixels()[i];
    const Eigen::Vector3d v = transform * Eigen::Vector3d(l.x, l.y, l.z);
    std::uint8_t bytes[3];
    for (int k = 0; k < 3; ++k) {
      double value = 255.0 * std::pow(std::clamp(v[k], 0.0, 1.0), 1.0 / camera.gamma);
      if (camera.noise_sigma > 0.0) value += noise(random);
      bytes[k] = static_cast<std::uint8_t>(std::lround(std::clamp(value, 0.0, 255.0)));
    }
    image.pixels()[i] = {bytes[0], bytes[1], bytes[2]};
  }
  return image;
}

SyntheticTriple make_synthetic_triple(const SyntheticTripleOptions& options) {
  if (options.width <= 0 || options.height <= 0) throw Error("make_synthetic_triple: empty image size");
  synth::Scene scene = synth::default_indoor_scene();
  PinholeIntrinsics intrinsics = PinholeIntrinsics::kinect_v1();
  const double scale = static_cast<double>(options.width) / intrinsics.width;
  intrinsics = {intrinsics.fx * scale, intrinsics.fy * scale, (options.width - 1) / 2.0, (options.height - 1) / 2.0,
                options.width, options.height};
  // A view of the table from the front-right, high enough to see the props and the floor.
  const Pose pose = synth::look_at({1.0, -1.25, 1.45}, scene.look_at);

  SyntheticTriple triple;
  triple.real = synth::render_frame(scene, intrinsics, pose).radiance;
  scene.materials.push_back({{options.virtual_albedo, 0.05, 10.0}, "virtual"});
  const int material = static_cast<int>(scene.materials.size()) - 1;
  scene.objects.push_back(
      {"virtual_sphere", synth::Sphere{{0.05, -0.12, 0.75 + options.virtual_radius}, options.virtual_radius}, material});
  triple.real_virtual = synth::render_frame(scene, intrinsics, pose).radiance;
  CameraColorTransform clean = options.camera;
  triple.camera = apply_camera(triple.real, options.camera);
  clean.noise_sigma = 0.0;
  triple.truth = apply_camera(triple.real_virtual, clean);
  return triple;
}

double mean_delta_e(const ColorImage& first, const ColorImage& second, const Mask& mask) {
  if (!first.same_shape(second) || !first.same_shape(mask)) throw Error("mean_delta_e: images differ in size");
  double sum = 0.0;
  std::int64_t count = 0;
  for (std::size_t i = 0; i < first.size(); ++i) {
    if (mask.pixels()[i] == 0) continue;
    sum += colormap::ciede2000(colormap::linear_srgb_to_lab(colormap::decode_srgb8(first.pixels()[i])),
                               colormap::linear_srgb_to_lab(colormap::decode_srgb8(second.pixels()[i])));
    ++count;
  }
  if (count == 0) throw Error("mean_delta_e: the mask is empty");
  return sum / static_cast<double>(count);
}

}  // namespace relight::truth
