#pragma once
// Diffuse reflectance per pixel (Knecht eq. 4.13), in linear RGB:
//
//   k_d(x) = L(x) / D(x),   D(x) = A + sum_l E_l(x) / pi            (shading.h)
//
// i.e. Knecht's k_d = I / sum_i I_i <omega_i . n>+ with the ambient term A of shading.h added
// to the denominator (the synthetic scene's constant environment; zero for lights sampled from
// the whole probe). L is the camera colour after highlight removal, linearised (sRGB decode);
// exposure is taken as 1, so k_d is only as absolute as the light set's calibration.
//
// Shadows are NOT modelled: every light facing the surface is assumed to reach it, so a pixel in
// a cast shadow gets a k_d that is too dark. Inter-reflections are not modelled either.
//
// A pixel is invalid (mask 0, k_d = 0) when it has no position or normal, when D's luminance is
// below min_shading (too little light for a stable ratio), or when the colour's luminance is
// below min_brightness (dark pixels are dominated by quantisation and noise).
//
// A valid pixel is marked 2 instead of 1 when it looks into the specular lobe of a light that
// faces it: <omega_o . r_l> > lobe_cos_min (r_l the light's mirror direction, omega_o towards
// the camera). There a glossy material's broad sheen, neither white nor bright enough to be
// removed as a highlight, adds to L and raises k_d along the light's colour (the synthetic
// table, k_s 0.15 and n 20, gains ~0.1 within ~35 degrees of the mirror direction). K-means
// clusters only the pixels marked 1 and then assigns the others to the nearest centre, so that
// sheen cannot take a cluster of its own. 0.8 (37 degrees) keeps n = 20 lobes below ~1 % of
// their peak outside the cone; 1 marks nothing.
//
// A pixel of an 8-bit image with a channel at or above clip_code is marked 3 (clipped), k_d 0:
// where the camera saturates (an over-exposed white desk) its value is only a lower bound, and
// the ratio would take a clipped channel's deficit for the surface's colour (a cyan "white").
// K-means leaves it out, and it takes the material of the nearest clustered pixel of its surface
// (fill_clipped_labels), so the renderer shades it with the albedo of its unclipped parts.
#include <cstdint>

#include "relight/brdf/shading.h"
#include "relight/core/image.h"

namespace relight::brdf {

/// The values of the k_d validity mask.
inline constexpr std::uint8_t kKdMarkInvalid = 0;
inline constexpr std::uint8_t kKdMarkValid = 1;
inline constexpr std::uint8_t kKdMarkNearLobe = 2;  ///< valid, in a light's specular lobe
inline constexpr std::uint8_t kKdMarkClipped = 3;   ///< the camera saturated: k_d unknown
[[nodiscard]] inline bool has_kd(std::uint8_t validity) {
  return validity == kKdMarkValid || validity == kKdMarkNearLobe;
}

struct DiffuseOptions {
  float min_shading = 0.02f;     ///< radiance units (luminance of D)
  float min_brightness = 0.004f;  ///< linear luminance of the pixel colour
  float max_kd = 2.f;            ///< k_d channels are clamped to [0, max_kd]
  float lobe_cos_min = 0.8f;     ///< <omega_o . r_l> above which a valid pixel is marked 2
  int clip_code = kClippedCode;  ///< 8-bit inputs: a channel at or above this is clipped (mark 3)
  int threads = 0;
};

/// k_d and validity for every pixel. `color` is the 8-bit sRGB camera image (highlights removed);
/// positions and normals are camera-frame (reconstruct/), lights from to_camera_frame().
void estimate_diffuse(const ColorImage& color, const PositionMap& positions, const NormalMap& normals,
                      const ShadingLights& lights, const DiffuseOptions& options, RadianceImage& kd, Mask& valid);

/// The same for a linear-RGB input (tests on exact radiance, renderer output).
void estimate_diffuse(const RadianceImage& linear, const PositionMap& positions, const NormalMap& normals,
                      const ShadingLights& lights, const DiffuseOptions& options, RadianceImage& kd, Mask& valid);

}  // namespace relight::brdf
