#pragma once
// Reinhard's key adapted to the scene every frame (Reinhard et al. 2002, the dissertation's
// §5.1/§5.2.10 tone mapper; tone_map.h has the operator):
//
//   L̄_w = exp(mean over lit pixels of log(delta + Y))        eq. 1, on L_rv (linear radiance)
//   s = a / L̄_w                                             eq. 2, a = the key (0.18: middle grey)
//   L_white = max(1, s * max channel)                        eq. 4's white: the scene's brightest
//                                                            channel maps to 1, nothing clips
//
// Both world luminances are smoothed over time in the log domain, exponentially with the time
// constant tau of the frames' timestamps (weight 1 - exp(-dt / tau)), as an eye or a camera's
// auto-exposure adapts: a light switched on or off moves the key within a few tau, and a single
// frame's specular flash does not pump the whole picture.
//
// Departure from the paper: Reinhard's eq. 1 averages over every pixel; here pixels without
// light (Y = 0: where the reconstruction has no surface, DIR renders nothing) are left out, or
// holes in the depth would brighten the picture. Every second pixel of every second row is
// enough for the average (a quarter of the logarithms, the same key within 0.5 %).
#include <cstdint>

#include "relight/colormap/tone_map.h"
#include "relight/core/image.h"

namespace relight::colormap {

struct SceneLuminance {
  double log_average = 0.0;  ///< L̄_w of eq. 1 over the lit pixels (0: none)
  double max = 0.0;          ///< the largest channel of a lit pixel (tone_map.h's curve runs on it)
  std::int64_t pixels = 0;   ///< lit pixels averaged
};

/// Eq. 1 over every `stride`-th pixel of every `stride`-th row of linear radiance.
[[nodiscard]] SceneLuminance scene_luminance(const RadianceImage& radiance, int stride = 2);

struct ToneMapOptions {
  ToneOperator op = ToneOperator::Exposure;
  float exposure = 1.f;       ///< Exposure: the fixed scale
  double key = 0.18;          ///< Reinhard: a of eq. 2
  double adaptation_s = 0.5;  ///< Reinhard: tau, seconds (0: no smoothing)
};

/// This frame's operator: Exposure's fixed scale, or Reinhard's adapted from `previous` (the last
/// frame's, none on the first) over `interval_s` seconds towards `scene`. A frame without lit
/// pixels keeps the previous adaptation (or s = 1 on the first).
[[nodiscard]] ToneMap adapt_tone_map(const ToneMapOptions& options, const SceneLuminance& scene,
                                     const ToneMap* previous, double interval_s);

}  // namespace relight::colormap
