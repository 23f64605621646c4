#pragma once
// CIEDE2000 colour difference (CIE 142-2001), implemented after Sharma, Wu & Dalal, "The
// CIEDE2000 Color-Difference Formula: Implementation Notes, Supplementary Test Data, and
// Mathematical Observations", Color Res. Appl. 30(1), 2005 (kL = kC = kH = 1). The hue mean and
// hue difference follow the paper's eqs. 10-14 (including the zero-chroma cases), so the
// result matches its 34 published test pairs to 4 decimals.
#include "relight/colormap/color_space.h"

namespace relight::colormap {

struct Lab {
  double L = 0, a = 0, b = 0;
};

[[nodiscard]] double ciede2000(const Lab& first, const Lab& second);
[[nodiscard]] inline double ciede2000(const LabPixel& first, const LabPixel& second) {
  return ciede2000(Lab{first.x, first.y, first.z}, Lab{second.x, second.y, second.z});
}

}  // namespace relight::colormap
