#pragma once
// The tone-mapping operator TM shared by the renderer, the colour mapping and the composites
// (Knecht §4.5, eq. 4.28: the mapping works on TM(L_r) and TM(L_rv), i.e. on what the renderer
// would display). Two operators, one formula: with s = ToneMap::exposure and
// L = k * s * max(c_r, c_g, c_b) (k = 1 for Reinhard, 0 for Exposure),
//
//   TM(c) = clamp(s * c * (1 + L / L_white^2) / (1 + L), 0, 1)   per linear-RGB channel
//
//   Exposure (k = 0): clamp(s * c, 0, 1). A linear exposure followed by clipping is what an 8-bit
//     camera does to radiance before its transfer curve, so virtual objects saturate exactly
//     like the real scene in the camera image.
//   Reinhard (k = 1): the photographic operator of Reinhard et al. 2002 (the dissertation's
//     §5.1/§5.2.10 tone mapper), eq. 4, with the colour scaled by the curve's ratio L_d / L:
//     s = a / L̄_w is eq. 2's key over the log-average world luminance (eq. 1,
//     adaptive_tone_map.h), L_white the scaled value that maps to 1. Highlights roll off towards
//     1 instead of clipping; L_white = 1 gives Exposure's curve below 1.
//     Departure: Reinhard compresses the luminance Y and scales the colour with it, so a
//     saturated highlight (a red pebble's) still clips in its strongest channel, and loses its
//     hue, before Y reaches the white. The curve here runs on the largest channel instead: no
//     channel of a colour below L_white reaches 1 and every colour keeps its channel ratios.
//
#include <algorithm>
#include <array>

#include "relight/core/named_values.h"
#include "relight/core/pixel.h"

namespace relight::colormap {

enum class ToneOperator { Exposure, Reinhard };
inline constexpr std::array<NamedValue<ToneOperator>, 2> kToneOperatorNames{
    {{"exposure", ToneOperator::Exposure}, {"reinhard", ToneOperator::Reinhard}}};

struct ToneMap {
  static constexpr const char* type_name = "ToneMap";
  ToneOperator op = ToneOperator::Exposure;
  float exposure = 1.f;               ///< s: the linear scale (Reinhard: key / log-average luminance)
  float inverse_white_squared = 0.f;  ///< Reinhard: 1 / L_white^2 in scaled units; 0: never burns out
  /// Reinhard's adapted world values this frame's s and L_white come from (0 for Exposure): what
  /// the next frame adapts from, and what the report shows.
  float log_average_luminance = 0.f;  ///< L̄_w of eq. 1
  float white = 0.f;                  ///< the largest channel, unscaled
};

/// k of the header's formula: 1 where the operator compresses, 0 where it only scales.
[[nodiscard]] inline float compression(const ToneMap& tm) { return tm.op == ToneOperator::Reinhard ? 1.f : 0.f; }

/// The factor (1 + L / L_white^2) / (1 + L) for the scaled value L = k * s * max channel (clamped at 0).
[[nodiscard]] inline float tone_factor(float scaled_value, const ToneMap& tm) {
  const float l = std::max(0.f, scaled_value);
  return (1.f + l * tm.inverse_white_squared) / (1.f + l);
}

[[nodiscard]] inline Float3 tone_map(const Float3& linear, const ToneMap& tm) {
  const Float3 scaled{tm.exposure * linear.x, tm.exposure * linear.y, tm.exposure * linear.z};
  const float f = tone_factor(compression(tm) * std::max(std::max(scaled.x, scaled.y), scaled.z), tm);
  return {std::clamp(scaled.x * f, 0.f, 1.f), std::clamp(scaled.y * f, 0.f, 1.f), std::clamp(scaled.z * f, 0.f, 1.f)};
}

}  // namespace relight::colormap
