#pragma once
// Highlight removal (Knecht §4.4.1, after Ortiz & Torres): specular highlights would make the
// diffuse estimate of eq. 4.13 far too bright, so they are found and painted over first.
//
//  1. Colour -> HSI on the 8-bit sRGB values scaled to [0, 1]: I = (R + G + B) / 3,
//     S = 1 - min(R, G, B) / I (S = 0 for black).
//  2. Highlight where I >= intensity_min (0.9) and S <= saturation_max (0.1): white highlights
//     of a (near-)white light on any material.
//  3. The mask is dilated with a disk of radius dilate_radius (4 px: every pixel whose Euclidean
//     distance to a highlight pixel is <= 4), catching the highlight's darker fringe.
//  4. Each masked pixel takes the colour of the nearest unmasked pixel: square rings of growing
//     radius (Chebyshev distance 1, 2, ...) are searched, and in the first ring that holds an
//     unmasked pixel the one at the smallest Euclidean distance wins (ties: first in row-major
//     order). Beyond fill_radius_max the pixel keeps its colour.
//
// Limits: a white or very bright unsaturated surface (a lit white wall) is masked too; callers
// treat masked pixels as "colour unreliable", not as "specular".
#include "relight/core/image.h"

namespace relight::brdf {

struct HighlightOptions {
  float intensity_min = 0.9f;
  float saturation_max = 0.1f;
  int dilate_radius = 4;
  int fill_radius_max = 64;
  int threads = 0;  ///< 0 = worker_count(0)
};

/// Step 1-2 for one colour.
[[nodiscard]] bool is_highlight(Rgb8 color, const HighlightOptions& options = {});

/// Steps 1-4. `cleaned` and `mask` are resized to the input; mask is 1 on removed pixels.
void remove_highlights(const ColorImage& color, const HighlightOptions& options, ColorImage& cleaned, Mask& mask);

/// Step 3 alone: disk dilation of a binary mask (exposed for tests).
void dilate_disk(const Mask& input, int radius, Mask& output, int threads = 0);

}  // namespace relight::brdf
