#pragma once
// The camera's sensor noise as a function of intensity, for adding matching noise to the virtual
// layer (dissertation §6.4's "camera artefacts"; Klein & Murray 2010). Sensor noise grows with
// the signal (photon shot noise) and the camera's curve reshapes it, so one sigma does not fit:
// the profile keeps one per intensity band and channel, in 8-bit code values of the image.
//
// Method: Immerkaer's operator ("Fast noise variance estimation", CVIU 1996), the 3x3 kernel
//   N = [1 -2 1; -2 4 -2; 1 -2 1]
// which cancels constant, linear and most of the quadratic signal; on i.i.d. noise of sigma its
// response is Gaussian with sigma 6 sigma. Only flat pixels count (Sobel gradient of the 3x3 mean
// below flat_gradient, so edges and texture do not pass for noise), nothing clipped in the 3x3
// window (clipping truncates noise), and each band takes the median |response|, robust to what
// texture remains: sigma = median |N * I| / (6 * 0.6745). A band with fewer than min_samples flat
// pixels borrows its neighbours' (interpolated).
#include <array>
#include <cstdint>

#include "relight/core/image.h"

namespace relight::colormap {

inline constexpr int kNoiseBands = 8;  ///< intensity bands of 32 code values

struct NoiseEstimationOptions {
  int stride = 6;              ///< pixels: every stride-th pixel of every stride-th row
  double flat_gradient = 6.0;  ///< code values per pixel of the 3x3 mean's Sobel gradient, at most
  int min_samples = 64;        ///< flat pixels a band needs for its own estimate
};

struct NoiseProfile {
  /// Per band (by the pixel's 3x3 mean luminance code: band = code / 32) and channel (R, G, B),
  /// the noise sigma in 8-bit code values.
  std::array<std::array<float, 3>, kNoiseBands> sigma{};
  std::array<int, kNoiseBands> samples{};  ///< flat pixels measured per band
  [[nodiscard]] bool valid() const;        ///< any band measured
  /// Sigma of `channel` at 8-bit code `code` (0-255), linear between band centres.
  [[nodiscard]] float at(float code, int channel) const;
};

[[nodiscard]] NoiseProfile estimate_camera_noise(const ColorImage& image, const NoiseEstimationOptions& options = {});

}  // namespace relight::colormap
