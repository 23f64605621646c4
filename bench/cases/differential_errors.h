#pragma once
// How far a differential renderer's images are from the path tracer's, as the DIR cases report
// it (dir.cpp, specular.cpp): the composite in camera-linear space with a clamping tone map, the
// camera image being the reference's TM(L_r).
#include <algorithm>
#include <cmath>

#include "relight/core/image.h"
#include "relight/render/differential_images.h"

namespace relight::bench {

inline float tm(float x) { return std::clamp(x, 0.f, 1.f); }

inline Float3 tm(const Float3& c) { return {tm(c.x), tm(c.y), tm(c.z)}; }

/// Composite in camera-linear space, the camera image being `camera_real` (TM of a real image).
inline Float3 composite(const render::DifferentialImages& images, const RadianceImage& camera_real, std::size_t i) {
  const float c = images.virtual_coverage.pixels()[i];
  const Float3 with = tm(images.real_virtual.pixels()[i]);
  const Float3 delta = with - tm(images.real.pixels()[i]);
  return c * with + (1.f - c) * (tm(camera_real.pixels()[i]) + delta);
}

struct Errors {
  double delta_rel = 0.0;  ///< mean relative error of TM(L_rv) - TM(L_r) where the reference's exceeds 0.01
  double composite_rmse = 0.0;
};

inline Errors compare(const render::DifferentialImages& ours, const render::DifferentialImages& reference) {
  double diff = 0.0, norm = 0.0, squared = 0.0;
  for (std::size_t i = 0; i < ours.real.size(); ++i) {
    const Float3 c = composite(ours, reference.real, i) - composite(reference, reference.real, i);
    squared += dot(c, c);
    if (ours.virtual_coverage.pixels()[i] > 0.f || reference.virtual_coverage.pixels()[i] > 0.f) continue;
    const Float3 d_ref = tm(reference.real_virtual.pixels()[i]) - tm(reference.real.pixels()[i]);
    if (length(d_ref) <= 0.01f) continue;
    const Float3 d_ours = tm(ours.real_virtual.pixels()[i]) - tm(ours.real.pixels()[i]);
    diff += length(d_ours - d_ref);
    norm += length(d_ref);
  }
  return {norm > 0.0 ? diff / norm : 0.0, std::sqrt(squared / (3.0 * static_cast<double>(ours.real.size())))};
}

}  // namespace relight::bench
