#pragma once
// The tone-mapping operator TM shared by the renderer and the colour mapping (Knecht §4.5,
// eq. 4.28: the mapping works on TM(L_r) and TM(L_rv), i.e. on what the renderer would display).
//
//   TM(c) = clamp(exposure * c, 0, 1)   per linear-RGB channel
//
// A linear exposure followed by clipping is what an 8-bit camera does to radiance before its
// transfer curve, so the renderer's virtual objects saturate exactly like the real scene in the
// camera image. Keep this the only definition: the GLSL twin (colormap_shared.h,
// RELIGHT_COLORMAP_TONE_MAP) must stay identical.
#include <algorithm>

#include "relight/core/pixel.h"

namespace relight::colormap {

struct ToneMap {
  float exposure = 1.f;  ///< linear scale applied before clipping
};

[[nodiscard]] inline float tone_map(float linear, const ToneMap& tm) {
  return std::clamp(tm.exposure * linear, 0.f, 1.f);
}
[[nodiscard]] inline Float3 tone_map(const Float3& linear, const ToneMap& tm) {
  return {tone_map(linear.x, tm), tone_map(linear.y, tm), tone_map(linear.z, tm)};
}

}  // namespace relight::colormap
