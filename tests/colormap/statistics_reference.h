#pragma once
// The statistics-based mapping written the plain way (one pixel at a time, std::cbrt through
// linear_srgb_to_lab, one running double sum), as it was before the row-parallel, vectorised
// version in statistics_transfer_cpu.cpp: the tests hold the fast path to this.
#include "relight/colormap/statistics_transfer.h"

namespace relight::colormap::test {

inline void accumulate_reference(std::array<double, 3>& sum, std::array<double, 3>& sum_sq, const LabPixel& lab) {
  const double v[3] = {lab.x, lab.y, lab.z};
  for (std::size_t k = 0; k < 3; ++k) {
    sum[k] += v[k];
    sum_sq[k] += v[k] * v[k];
  }
}

inline LabSums masked_lab_sums_reference(const RadianceImage& real, const RadianceImage& real_virtual,
                                         const ColorImage& camera, const ToneMap& tm) {
  LabSums sums;
  for (std::size_t i = 0; i < real.size(); ++i) {
    const Float3& r = real.pixels()[i];
    const Rgb8& c = camera.pixels()[i];
    if (!is_statistics_pixel(r, real_virtual.pixels()[i], c, tm)) continue;
    ++sums.count;
    accumulate_reference(sums.source_sum, sums.source_sum_sq, linear_srgb_to_lab(tone_map(r, tm)));
    accumulate_reference(sums.target_sum, sums.target_sum_sq, linear_srgb_to_lab(decode_srgb8(c)));
  }
  return sums;
}

inline RadianceImage statistics_delta_reference(const RadianceImage& real, const RadianceImage& real_virtual,
                                                const ReinhardTransfer& transfer, const ToneMap& tm) {
  RadianceImage delta(real.width(), real.height());
  for (std::size_t i = 0; i < real.size(); ++i) {
    const Float3& r = real.pixels()[i];
    const Float3& rv = real_virtual.pixels()[i];
    delta.pixels()[i] = r == rv ? Float3{} : map_statistics(rv, transfer, tm) - map_statistics(r, transfer, tm);
  }
  return delta;
}

}  // namespace relight::colormap::test
