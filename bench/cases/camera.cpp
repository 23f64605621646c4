// camera/artefacts_640x480: the camera's look on the virtual layer (colormap/camera_look.h,
// render/dir/camera_look_stage.h) for one 640x480 frame: estimating the camera's blur and noise
// from its image, the image motion from two poses, and the composite with them on the layer.
// The camera is the synthetic camera's image of the table (synthetic_camera.h), blurred by a
// Gaussian of sigma 1.2 px and given noise of sigma sqrt(0.5 + 0.04 I) code values; the layer is
// the virtual sphere of that scene. "baseline" is the composite without artefacts, so
// artefacts_ms = ms - baseline_ms is what the look costs per frame (goal: <= 5 ms); sigma_px and
// noise_sigma_128 are what the estimators measured (truth: 1.2 and 2.4).
#include <cmath>

#include "bench.h"
#include "relight/colormap/camera_blur.h"
#include "relight/colormap/camera_look.h"
#include "relight/colormap/camera_noise.h"
#include "relight/colormap/color_space.h"
#include "relight/render/dir/camera_look_stage.h"
#include "relight/synth/camera_effects.h"
#include "relight/synth/raycast.h"
#include "relight/truth/synthetic_camera.h"

namespace {

using namespace relight;
using namespace relight::colormap;

constexpr double kTrueSigma = 1.2;

ColorImage blurred_noisy_camera(const RadianceImage& radiance) {
  const synth::ColorCameraEffects effects{kTrueSigma, 0.5, 0.04};
  return synth::add_color_noise(synth::encode_color(synth::blur_radiance(radiance, kTrueSigma)), effects, 5, 0);
}

bench::Json artefacts_640x480(const bench::Options& options) {
  const truth::SyntheticTriple triple = truth::make_synthetic_triple({.width = 640, .height = 480});
  const ColorImage camera = blurred_noisy_camera(triple.real);
  // The layer: the sphere covered (where it changes the picture by more than its bounce light
  // and shadow could: 0.05 in linear luminance), elsewhere the differential it makes.
  VirtualLayer layer{RadianceImage(640, 480), Image<float>(640, 480), RadianceImage(640, 480)};
  for (std::size_t i = 0; i < layer.coverage.size(); ++i) {
    const Float3 d = triple.real_virtual.pixels()[i] - triple.real.pixels()[i];
    if (0.2126f * d.x + 0.7152f * d.y + 0.0722f * d.z > 0.05f) {
      layer.coverage.pixels()[i] = 1.f;
      layer.virtual_color.pixels()[i] = triple.real_virtual.pixels()[i];
    } else {
      layer.delta.pixels()[i] = d;
    }
  }
  std::size_t covered = 0;
  for (const float c : layer.coverage.pixels()) covered += c > 0.f;
  // A camera turning by 0.5 degrees per frame about its y axis, 2 m in front of the scene.
  render::GBuffer gbuffer;
  gbuffer.distance = DepthMap(640, 480, 2.f);
  FrameInfo frame, previous;
  frame.intrinsics = previous.intrinsics = PinholeIntrinsics::kinect_v1();
  previous.timestamp = 0.0;
  frame.timestamp = 1.0 / 30.0;
  previous.camera_to_world = Pose::Identity();
  frame.camera_to_world = Pose(Eigen::AngleAxisd(0.5 * M_PI / 180.0, Eigen::Vector3d::UnitY()));

  CameraLook look;
  // One run is two frames as the camera_look stage makes them once both estimates are known: the
  // blur measured on one, the noise on the next (CameraLookOptions::alternate_estimates); ms and
  // baseline_ms are per frame, half of a run.
  const auto frame_with = [&](bool blur, bool noise) {
    look.motion = render::image_motion(gbuffer, frame, previous, 1.0 / 60.0);
    if (blur) {
      look.blur = estimate_camera_blur(camera, {}, Eigen::Vector2f(1.f, 0.f));
      look.blur_sigma_px = float(look.blur.sigma_px);
    }
    if (noise) look.noise = estimate_camera_noise(camera);
    look.seed = 3;
    (void)composite_layer(camera, layer, &look);
  };
  frame_with(true, true);
  const auto ours = [&] {
    frame_with(true, false);
    frame_with(false, true);
  };
  const auto baseline = [&] {
    (void)composite_layer(camera, layer, nullptr);
    (void)composite_layer(camera, layer, nullptr);
  };
  bench::Comparison times = bench::compare_interleaved(ours, baseline, options.repetitions);
  times.ms /= 2.0;
  times.baseline_ms /= 2.0;
  const double blur_ms =
      bench::median_ms([&] { (void)estimate_camera_blur(camera, {}, Eigen::Vector2f(1.f, 0.f)); }, options.repetitions);
  const double noise_ms = bench::median_ms([&] { (void)estimate_camera_noise(camera); }, options.repetitions);
  const double layer_ms = bench::median_ms([&] { (void)composite_layer(camera, layer, &look); }, options.repetitions);
  const double motion_ms =
      bench::median_ms([&] { (void)render::image_motion(gbuffer, frame, previous, 1.0 / 60.0); }, options.repetitions);
  bench::Json json = bench::comparison_json(times, "composite_without_artefacts");
  json["artefacts_ms"] = times.ms - times.baseline_ms;
  json["blur_estimate_ms"] = blur_ms;
  json["noise_estimate_ms"] = noise_ms;
  json["motion_ms"] = motion_ms;
  json["layer_ms"] = layer_ms - times.baseline_ms;  // the look on the layer: blur, motion blur, noise
  json["sigma_px"] = look.blur.sigma_px;
  json["true_sigma_px"] = kTrueSigma;
  json["blur_edges"] = look.blur.edges;
  json["noise_sigma_128"] = look.noise.at(128.f, 1);
  json["true_noise_sigma_128"] = std::sqrt(0.5 + 0.04 * 128.0);
  json["motion_px"] = look.motion.max_length();
  json["covered_pixels"] = covered;
  json["width"] = 640;
  json["height"] = 480;
  return json;
}

}  // namespace

RELIGHT_BENCH_CASE("camera/artefacts_640x480", artefacts_640x480);
