// camera/artefacts_640x480: the camera's look on the virtual layer (colormap/camera_look.h,
// render/dir/camera_look_stage.h) for one 640x480 frame: estimating the camera's blur and noise
// from its image, the image motion from two poses, and the composite with them on the layer.
// The camera is the synthetic camera's image of the table (synthetic_camera.h), blurred by a
// Gaussian of sigma 1.2 px and given noise of sigma sqrt(0.5 + 0.04 I) code values; the layer is
// the virtual sphere of that scene. "baseline" is the composite without artefacts, so
// artefacts_ms = ms - baseline_ms is what the look costs (goal: <= 5 ms); sigma_px and
// noise_sigma_128 are what the estimators measured (truth: 1.2 and 2.4).
#include <cmath>
#include <random>

#include "bench.h"
#include "relight/colormap/camera_blur.h"
#include "relight/colormap/camera_look.h"
#include "relight/colormap/camera_noise.h"
#include "relight/colormap/color_space.h"
#include "relight/render/dir/camera_look_stage.h"
#include "relight/truth/synthetic_camera.h"

namespace {

using namespace relight;
using namespace relight::colormap;

constexpr double kTrueSigma = 1.2;

ColorImage blurred_noisy_camera(const RadianceImage& radiance) {
  const int radius = static_cast<int>(std::ceil(4 * kTrueSigma));
  std::vector<float> weights;
  float total = 0.f;
  for (int k = -radius; k <= radius; ++k)
    total += weights.emplace_back(float(std::exp(-0.5 * k * k / (kTrueSigma * kTrueSigma))));
  for (float& w : weights) w /= total;
  RadianceImage horizontal(radiance.width(), radiance.height()), both(radiance.width(), radiance.height());
  for (int r = 0; r < radiance.height(); ++r)
    for (int c = 0; c < radiance.width(); ++c)
      for (int k = -radius; k <= radius; ++k)
        horizontal(r, c) += weights[std::size_t(k + radius)] * radiance(r, std::clamp(c + k, 0, radiance.width() - 1));
  for (int r = 0; r < radiance.height(); ++r)
    for (int c = 0; c < radiance.width(); ++c)
      for (int k = -radius; k <= radius; ++k)
        both(r, c) += weights[std::size_t(k + radius)] * horizontal(std::clamp(r + k, 0, radiance.height() - 1), c);
  std::mt19937_64 random(5);
  std::normal_distribution<double> gauss;
  ColorImage out(radiance.width(), radiance.height());
  for (std::size_t i = 0; i < out.size(); ++i) {
    const Float3 p = both.pixels()[i];
    const float linear[3] = {p.x, p.y, p.z};
    std::uint8_t codes[3];
    for (int ch = 0; ch < 3; ++ch) {
      const double code = 255.0 * linear_to_srgb(std::clamp(linear[ch], 0.f, 1.f));
      codes[ch] = static_cast<std::uint8_t>(
          std::clamp(std::lround(code + std::sqrt(0.5 + 0.04 * code) * gauss(random)), 0L, 255L));
    }
    out.pixels()[i] = {codes[0], codes[1], codes[2]};
  }
  return out;
}

bench::Json artefacts_640x480(const bench::Options& options) {
  const truth::SyntheticTriple triple = truth::make_synthetic_triple({.width = 640, .height = 480});
  const ColorImage camera = blurred_noisy_camera(triple.real);
  // The layer: the sphere where L_rv and L_r differ (coverage 1), its shadow as the delta.
  VirtualLayer layer{RadianceImage(640, 480), Image<float>(640, 480), RadianceImage(640, 480)};
  for (std::size_t i = 0; i < layer.coverage.size(); ++i) {
    const Float3 with = triple.real_virtual.pixels()[i], without = triple.real.pixels()[i];
    const Float3 d = with - without;
    if (std::max({std::abs(d.x), std::abs(d.y), std::abs(d.z)}) < 1e-6f) continue;
    const bool brighter = with.x + with.y + with.z > without.x + without.y + without.z;
    if (brighter) {
      layer.coverage.pixels()[i] = 1.f;
      layer.virtual_color.pixels()[i] = with;
    } else {
      layer.delta.pixels()[i] = d;
    }
  }
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
  const auto ours = [&] {
    look.motion = render::image_motion(gbuffer, frame, previous, 1.0 / 60.0);
    look.blur = estimate_camera_blur(camera, {}, Eigen::Vector2f(1.f, 0.f));
    look.blur_sigma_px = float(look.blur.sigma_px);
    look.noise = estimate_camera_noise(camera);
    look.seed = 3;
    (void)composite_layer(camera, layer, &look);
  };
  const auto baseline = [&] { (void)composite_layer(camera, layer, nullptr); };
  const bench::Comparison times = bench::compare_interleaved(ours, baseline, options.repetitions);
  const double estimate_ms = bench::median_ms(
      [&] {
        (void)estimate_camera_blur(camera, {}, Eigen::Vector2f(1.f, 0.f));
        (void)estimate_camera_noise(camera);
      },
      options.repetitions);
  bench::Json json = bench::comparison_json(times, "composite_without_artefacts");
  json["artefacts_ms"] = times.ms - times.baseline_ms;
  json["estimate_ms"] = estimate_ms;
  json["sigma_px"] = look.blur.sigma_px;
  json["true_sigma_px"] = kTrueSigma;
  json["blur_edges"] = look.blur.edges;
  json["noise_sigma_128"] = look.noise.at(128.f, 1);
  json["true_noise_sigma_128"] = std::sqrt(0.5 + 0.04 * 128.0);
  json["motion_px"] = look.motion.max_length();
  json["width"] = 640;
  json["height"] = 480;
  return json;
}

}  // namespace

RELIGHT_BENCH_CASE("camera/artefacts_640x480", artefacts_640x480);
