#pragma once
// What a real colour camera does to the image and the ray caster does not: a soft point spread
// (optics, demosaicing) and sensor noise that grows with the signal. Ground truth for the
// estimators of the camera's look (colormap/camera_blur.h, camera_noise.h).
//   blur:  a Gaussian of blur_sigma_px on the linear radiance, before the camera's curve;
//   noise: per channel, after the 8-bit encoding, N(0, sigma(I)) with
//          sigma(I)^2 = noise_floor + noise_gain I   (I: the 8-bit code; read noise plus a
//          shot-noise term proportional to the signal), rounded and clipped to [0, 255].
// Random numbers as kinect_noise.h: std::mt19937_64 seeded per (seed, frame, row), Box-Muller.
#include <cmath>
#include <cstdint>

#include "relight/core/image.h"

namespace relight::synth {

struct ColorCameraEffects {
  double blur_sigma_px = 0.0;
  double noise_floor = 0.0;  ///< code values^2
  double noise_gain = 0.0;   ///< code values^2 per code value
  [[nodiscard]] bool any() const { return blur_sigma_px > 0.0 || noise_floor > 0.0 || noise_gain > 0.0; }
  /// sigma(I) of the noise model above, code values.
  [[nodiscard]] double noise_sigma(double code) const { return std::sqrt(noise_floor + noise_gain * code); }
};

/// The Gaussian blur of the effects (clamped at the image border); the input when sigma is 0.
[[nodiscard]] RadianceImage blur_radiance(const RadianceImage& radiance, double sigma_px);
/// The noise of the effects on an 8-bit image; the same for (seed, frame) on any thread count.
[[nodiscard]] ColorImage add_color_noise(const ColorImage& image, const ColorCameraEffects& effects, std::uint64_t seed,
                                         std::uint64_t frame, int threads = 0);

}  // namespace relight::synth
