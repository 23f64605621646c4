#pragma once
// Kinect v1 depth noise, applied to exact ground-truth depth.
//
// Per valid pixel, in this order:
//  1. dropouts: at depth discontinuities (a neighbour within `edge_radius_px` differs by more
//     than edge_threshold_m + edge_threshold_rel * z, or is missing) with probability
//     `edge_dropout_probability`, and always at grazing angles (angle between the viewing ray
//     and the surface normal above `grazing_angle_deg`);
//  2. lateral noise: the depth is read at a pixel position jittered by N(0, lateral_sigma_px) in
//     u and v (bilinear where the four neighbours agree, nearest otherwise);
//  3. axial noise: z += N(0, sigma_z(z)) with sigma_z(z) = 0.0012 + 0.0019 (z - 0.4)^2 metres,
//     C. V. Nguyen, S. Izadi, D. Lovell, "Modeling Kinect Sensor Noise for Improved 3D
//     Reconstruction and Tracking", 3DIMPVT 2012, eq. (6) (for angles below ~60 degrees);
//  4. disparity quantisation: d = b f / z (b = 0.075 m, f = 580 px, the IR camera's focal
//     length), rounded to 1/8 pixel, z = b f / d;
//  5. range: depth below `min_depth` or beyond `max_depth` becomes 0 (missing).
// Random numbers come from std::mt19937_64 seeded per (seed, frame, row), so the result is the
// same for any thread count; Gaussians use Box-Muller on the raw 64-bit output, so they do not
// depend on the standard library's distribution implementations either.
#include <cstdint>
#include <string>

#include "relight/core/camera.h"
#include "relight/core/image.h"
#include "relight/core/named_values.h"

namespace relight::synth {

enum class NoiseModel { None, Kinect1 };
inline constexpr std::array<NamedValue<NoiseModel>, 2> kNoiseModelNames{
    {{"kinect1", NoiseModel::Kinect1}, {"none", NoiseModel::None}}};

/// One of kNoiseModelNames; throws relight::Error naming the choices otherwise.
[[nodiscard]] inline NoiseModel parse_noise(const std::string& name) {
  return parse_named(kNoiseModelNames, "noise model", name);
}
[[nodiscard]] inline const char* to_string(NoiseModel model) { return name_of(kNoiseModelNames, model); }

struct KinectNoiseOptions {
  bool axial = true;
  double lateral_sigma_px = 0.8;
  bool quantise = true;
  double baseline_m = 0.075;
  double focal_px = 580.0;
  double subpixel = 1.0 / 8.0;
  double min_depth = 0.5;
  double max_depth = 4.0;
  double grazing_angle_deg = 75.0;
  bool edge_dropouts = true;
  int edge_radius_px = 1;
  double edge_threshold_m = 0.01;
  double edge_threshold_rel = 0.04;
  double edge_dropout_probability = 0.75;
};

/// sigma_z(z) of Nguyen et al. 2012 in metres.
[[nodiscard]] double kinect_axial_sigma(double z);
/// Depth after rounding its disparity b f / z to the sub-pixel grid.
[[nodiscard]] double quantise_depth(double z, const KinectNoiseOptions& options);

/// Noisy depth from exact depth and camera-frame normals (same size). Missing input stays
/// missing. threads = 0 uses all hardware threads.
[[nodiscard]] DepthMap apply_kinect_noise(const DepthMap& depth, const NormalMap& normals,
                                          const PinholeIntrinsics& intrinsics, const KinectNoiseOptions& options,
                                          std::uint64_t seed, std::uint64_t frame, int threads = 0);

}  // namespace relight::synth
