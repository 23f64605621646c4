#pragma once
// The sRGB transfer curve (IEC 61966-2-1), shared by everything that turns linear light into
// 8-bit pictures or reads 8-bit colours as light: the colour mapping and composites, the BRDF
// estimation and its preview, the light probes' default response, material textures.
#include <array>
#include <cstdint>

#include "relight/core/pixel.h"

namespace relight {

/// sRGB transfer curve (IEC 61966-2-1) on [0, 1]: encoded -> linear and back.
[[nodiscard]] float srgb_to_linear(float encoded);
[[nodiscard]] float linear_to_srgb(float linear);
/// 8-bit sRGB -> linear through a 256-entry table (exact to float rounding).
[[nodiscard]] float srgb8_to_linear(std::uint8_t encoded);
/// That table (the curve evaluated in double precision), for loops over many pixels.
[[nodiscard]] const std::array<float, 256>& srgb8_linear_table();
[[nodiscard]] Float3 decode_srgb8(const Rgb8& pixel);
/// Linear -> 8-bit sRGB, clamped to [0, 1] and rounded to nearest: exactly
/// lround(255 linear_to_srgb(c)), by a search over the 255 thresholds between codes (no pow).
[[nodiscard]] std::uint8_t encode_srgb8_channel(float linear);
[[nodiscard]] Rgb8 encode_srgb8(const Float3& linear);

}  // namespace relight
