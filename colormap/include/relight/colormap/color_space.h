#pragma once
// Colour spaces of the statistics-based mapping (Knecht §4.5.3): the transform
// f = linear sRGB -> XYZ -> CIELab with illuminant E, and the sRGB transfer curve.
//
// Illuminant E (equal energy, x = y = 1/3) instead of D65 so that RGB white (1,1,1) maps to
// XYZ (1,1,1) = the Lab reference white, i.e. L* = 100, a* = b* = 0: the Reinhard transfer then
// moves colours relative to a neutral white, which is what a white-balance correction does.
// The matrix is the standard primaries-to-XYZ construction (SMPTE RP 177) for the sRGB
// primaries R (0.64, 0.33), G (0.30, 0.60), B (0.15, 0.06) with white point E:
//   M = [P_r P_g P_b] * diag(S), P_c = (x/y, 1, (1-x-y)/y) of primary c, S = [P_r P_g P_b]^-1 (1,1,1)
// Every row of M sums to 1 (white -> E). Values below are M and M^-1 to 10 digits.
//
// Lab (CIE 1976) with white (Xn, Yn, Zn) = (1, 1, 1):
//   L* = 116 g(Y) - 16, a* = 500 (g(X) - g(Y)), b* = 200 (g(Y) - g(Z)),
//   g(t) = t^(1/3) for t > (6/29)^3, else t / (3 (6/29)^2) + 4/29
// The linear branch extends to negative t, so out-of-gamut and difference colours round-trip.
#include <algorithm>
#include <bit>
#include <cstdint>

#include "relight/core/pixel.h"
#include "relight/core/srgb.h"

namespace relight::colormap {

/// Linear sRGB -> XYZ, white point E (rows: X, Y, Z).
inline constexpr float kLinearSrgbToXyzE[3][3] = {
    {0.4969210174f, 0.3390896921f, 0.1639892905f},
    {0.2562248996f, 0.6781793842f, 0.0655957162f},
    {0.0232931727f, 0.1130298974f, 0.8636769299f},
};
/// XYZ (white point E) -> linear sRGB: the inverse of kLinearSrgbToXyzE.
inline constexpr float kXyzEToLinearSrgb[3][3] = {
    {2.6896551724f, -1.2758620690f, -0.4137931034f},
    {-1.0221081721f, 1.9782866167f, 0.0438215555f},
    {0.0612244898f, -0.2244897959f, 1.1632653061f},
};

/// delta = 6/29 of the Lab curve g: g is a cube root above delta^3 and linear below.
inline constexpr float kLabDelta = 6.f / 29.f;
inline constexpr float kLabDeltaCubed = kLabDelta * kLabDelta * kLabDelta;
inline constexpr float kLabLinearSlope = 1.f / (3.f * kLabDelta * kLabDelta);

/// Cube root of a positive, normal float to <= 5e-7 relative (std::cbrt: 1e-7), for the hot
/// loops of the statistics-based mapping, where std::cbrt (a libm call, not vectorisable) cost
/// most of the time. x^(-1/3) is guessed from the float's bits (the exponent field is a
/// log2, divided by -3; the integer division is done in float so that SSE2 can vectorise it),
/// refined by three Newton steps y <- y (4/3 - x/3 y^3) that need no division (the error
/// squares each step: 8e-2, 6e-3, 4e-5, 5e-7), and cbrt(x) = x * y^2. Zero, negative, denormal
/// and non-finite x give garbage: callers select another branch for those.
[[nodiscard]] inline float fast_cbrt(float x) {
  constexpr std::int32_t kMagic = 0x54a2fa8c;  // (4/3) * (127 - 0.045) * 2^23: bias of -log2(x)/3
  const auto bits = std::bit_cast<std::int32_t>(x);
  float y = std::bit_cast<float>(kMagic - static_cast<std::int32_t>(static_cast<float>(bits) * (1.f / 3.f)));
  // Written out, not looped: a loop here keeps the callers' loops from vectorising.
  const float third_x = x * (1.f / 3.f);
  y = y * (4.f / 3.f - third_x * y * y * y);
  y = y * (4.f / 3.f - third_x * y * y * y);
  y = y * (4.f / 3.f - third_x * y * y * y);
  return x * y * y;
}

/// The Lab curve g(t) with fast_cbrt (same branches as lab_g in color_space.cpp); branch-free
/// (a select) so that loops over many values vectorise.
[[nodiscard]] inline float lab_g_fast(float t) {
  const float cube_root = fast_cbrt(std::max(t, kLabDeltaCubed));
  return t > kLabDeltaCubed ? cube_root : t * kLabLinearSlope + 4.f / 29.f;
}

/// CIELab colour (L* in [0, 100] for colours in gamut), stored in Float3 as (L, a, b).
using LabPixel = Float3;

[[nodiscard]] Float3 linear_srgb_to_xyz(const Float3& rgb);
[[nodiscard]] Float3 xyz_to_linear_srgb(const Float3& xyz);
[[nodiscard]] LabPixel xyz_to_lab(const Float3& xyz);
[[nodiscard]] Float3 lab_to_xyz(const LabPixel& lab);
/// f of eq. 4.30: linear sRGB -> CIELab (illuminant E), and its inverse.
[[nodiscard]] LabPixel linear_srgb_to_lab(const Float3& rgb);
[[nodiscard]] Float3 lab_to_linear_srgb(const LabPixel& lab);

// The sRGB curve lives in core (srgb.h); the colour mapping names it as its own.
using relight::decode_srgb8;
using relight::encode_srgb8;
using relight::encode_srgb8_channel;
using relight::linear_to_srgb;
using relight::srgb8_to_linear;
using relight::srgb_to_linear;

}  // namespace relight::colormap
