#pragma once
// From an 8-bit probe image (a webcam fisheye) to linear radiance.
//
//   L = f^-1(code) / exposure, per channel,
// with f^-1 the inverse camera response: sRGB's decoding by default (what a webcam approximates),
// or a measured curve (a text file of 256 lines "r g b": the relative linear radiance of each
// code value, non-decreasing, e.g. from Debevec & Malik's calibration).
//
// Clipped light sources. An LDR camera saturates on every lamp, so a probe's brightest sources
// come out orders of magnitude too dark and the shadows they cast vanish. Like Knecht's system
// (dissertation §6.2.2, after Landis 2002) relight expands the saturated range: a pixel whose
// brightest channel m (in [0, 1]) exceeds `clip_threshold` t is scaled by
//   g = 1 + (clip_gain - 1) * ((m - t) / (1 - t))^2,
// so a fully saturated pixel gets clip_gain times its decoded value and the expansion is smooth
// at the threshold. It is a rough stand-in for the radiance a clipped lamp really has (an HDR
// probe is the cure); `clipped_share` tells how much of the probe it touched.
#include <array>
#include <filesystem>

#include "relight/core/image.h"

namespace relight::lights {

struct ProbeResponse {
  /// Linear value of each code value, per channel (R, G, B); sRGB decoding by default.
  std::array<std::array<float, 256>, 3> inverse = srgb_inverse();
  double exposure = 1.0;         ///< divides the decoded values (relative exposure of the probe camera)
  double clip_threshold = 0.96;  ///< brightest channel above this is expanded (Landis)
  double clip_gain = 16.0;       ///< gain of a fully saturated pixel; 1 = no expansion

  [[nodiscard]] static std::array<std::array<float, 256>, 3> srgb_inverse();
};

/// Reads a response curve file (see above). Throws relight::Error naming the file and the line
/// (not 256 lines of 3 finite non-negative numbers, or a channel that decreases).
[[nodiscard]] ProbeResponse read_probe_response(const std::filesystem::path& path);

struct LdrProbe {
  RadianceImage radiance;
  double clipped_share = 0.0;  ///< share of pixels whose brightest channel exceeded clip_threshold
};

/// Decodes an 8-bit probe with `response` (see above). Throws relight::Error on a bad response
/// (exposure or gain not positive, threshold outside (0, 1)).
[[nodiscard]] LdrProbe radiance_from_ldr(const ColorImage& image, const ProbeResponse& response);

}  // namespace relight::lights
