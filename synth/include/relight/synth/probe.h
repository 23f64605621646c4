#pragma once
// The HDR light probe: what an equidistant 180-degree fisheye camera sees from a point above
// the table, looking straight up. Light sources appear as small spheres of constant radiance
// colour * intensity / (pi r^2) (so that their integrated intensity matches the point light
// used for shading), the sky shows the constant environment radiance, and any geometry in view
// is shaded with the same model as the colour camera. Values are linear radiance (no exposure,
// no white balance); sequence.h writes the image as probe.hdr.
#include <Eigen/Core>

#include "relight/core/camera.h"
#include "relight/core/image.h"
#include "relight/synth/raycast.h"
#include "relight/synth/scene.h"

namespace relight::synth {

struct LightProbe {
  FisheyeCamera camera;  ///< 512x512, 180 degrees by default
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  /// Columns: the probe's x (image right), y (image down) and z (optical axis) in the world.
  Eigen::Matrix3d probe_to_world = Eigen::Matrix3d::Identity();
  int samples_per_axis = 2;  ///< supersampling per pixel (s x s rays)
};

/// At scene.probe_position, optical axis world +z (up), image x = world x, image y = world y.
[[nodiscard]] LightProbe default_probe(const Scene& scene);

/// Linear radiance arriving along a ray: emitters, then geometry (shaded), then the sky.
[[nodiscard]] Eigen::Vector3d incoming_radiance(const Scene& scene, const Ray& ray);

/// The probe camera's sensor noise: every pixel channel scaled by (1 + sigma * N(0, 1)) (clamped
/// at 0), independently per frame; the same (seed, frame) give the same noise.
[[nodiscard]] RadianceImage add_probe_noise(RadianceImage probe, double sigma, std::uint64_t seed, std::uint64_t frame);

/// Renders the probe image; pixels outside the image circle are 0. threads = 0: all hardware.
[[nodiscard]] RadianceImage render_probe(const Scene& scene, const LightProbe& probe, int threads = 0);

}  // namespace relight::synth
