#pragma once
// Statistics-based colour mapping (Knecht §4.5.3) on the CPU.
//
//   tau_st(c) = f^-1(tau_ct(f(TM(c))))                                        (eq. 4.30)
// f: linear sRGB -> CIELab, illuminant E (color_space.h); TM: tone_map.h. tau_ct is Reinhard's
// per-channel statistics transfer in Lab, moving the statistics of the tone-mapped real-scene
// rendering (source s = f(TM(L_r))) onto those of the camera image (target t = f(L_cam)):
//   tau_ct(x)_k = sigma_t,k / sigma_s,k * (x_k - mu_s,k) + mu_t,k,  k in {L, a, b}  (eqs. 4.35-4.38)
// Means and standard deviations (population, eqs. 4.31-4.34) are taken exactly over the *valid*
// pixels, the same set for source and target:
//   valid(p) = L_r(p) finite, L_rv(p) == L_r(p) (no virtual object there), TM(L_r(p)) != 0 and
//              camera(p) != (0,0,0) (black/invalid pixels carry no colour information).
// Sums run in double (per row, then added in row order, so that the row-parallel result does not
// depend on the thread count); a channel with sigma_s = 0 keeps scale 1 (only the mean shifts), and no
// valid pixel at all gives the identity transfer.
//
// The difference image and the composite (eqs. 4.28-4.29, camera-linear sRGB):
//   delta_L = tau_st(L_rv) - tau_st(L_r),   L_final = L_cam + delta_L
// delta_L is exactly 0 where L_rv == L_r (the two terms are the same number).
#include <array>
#include <cstdint>

#include "relight/colormap/color_space.h"
#include "relight/colormap/tone_map.h"
#include "relight/core/image.h"

namespace relight::colormap {

/// Mean and population standard deviation per Lab channel over `count` pixels.
struct LabStatistics {
  std::int64_t count = 0;
  std::array<double, 3> mean{};
  std::array<double, 3> stddev{};
};

/// Raw sums of the reduction, so that partial results (CPU or GPU work groups) can be added up.
struct LabSums {
  std::int64_t count = 0;
  std::array<double, 3> source_sum{}, source_sum_sq{};
  std::array<double, 3> target_sum{}, target_sum_sq{};
  LabSums& operator+=(const LabSums& other);
};

struct TransferStatistics {
  LabStatistics source;  ///< f(TM(L_r)) over valid pixels
  LabStatistics target;  ///< f(L_cam) over the same pixels
};
[[nodiscard]] TransferStatistics statistics_from_sums(const LabSums& sums);

/// The valid-pixel rule above, for one pixel.
[[nodiscard]] bool is_statistics_pixel(const Float3& real, const Float3& real_virtual, const Rgb8& camera,
                                       const ToneMap& tm);

/// The masked sums of eqs. 4.31-4.34 on `threads` threads (0 = all, see relight::worker_count);
/// the result is the same for every thread count. All images must have the same shape (else
/// relight::Error). The cube roots of the Lab conversion use fast_cbrt (<= 5e-7 relative).
[[nodiscard]] LabSums masked_lab_sums(const RadianceImage& real, const RadianceImage& real_virtual,
                                      const ColorImage& camera, const ToneMap& tm, int threads = 0);
/// statistics_from_sums(masked_lab_sums(...)).
[[nodiscard]] TransferStatistics masked_lab_statistics(const RadianceImage& real, const RadianceImage& real_virtual,
                                                       const ColorImage& camera, const ToneMap& tm, int threads = 0);

/// tau_ct as scale/offset per Lab channel: x' = scale * x + offset.
struct ReinhardTransfer {
  std::array<float, 3> scale{1.f, 1.f, 1.f};
  std::array<float, 3> offset{0.f, 0.f, 0.f};

  [[nodiscard]] static ReinhardTransfer from(const TransferStatistics& statistics);
  [[nodiscard]] LabPixel apply(const LabPixel& lab) const {
    return {scale[0] * lab.x + offset[0], scale[1] * lab.y + offset[1], scale[2] * lab.z + offset[2]};
  }
};

/// tau_st(c) of eq. 4.30 for one linear radiance c.
[[nodiscard]] Float3 map_statistics(const Float3& radiance, const ReinhardTransfer& transfer, const ToneMap& tm);

/// delta_L = tau_st(L_rv) - tau_st(L_r) per pixel (map_statistics with fast_cbrt, row-parallel);
/// resizes `delta`.
void statistics_delta(const RadianceImage& real, const RadianceImage& real_virtual, const ReinhardTransfer& transfer,
                      const ToneMap& tm, RadianceImage& delta, int threads = 0);

/// Statistics + transfer + delta in one call (the CPU stage's work).
[[nodiscard]] ReinhardTransfer statistics_color_map(const RadianceImage& real, const RadianceImage& real_virtual,
                                                    const ColorImage& camera, const ToneMap& tm, RadianceImage& delta,
                                                    int threads = 0);

/// L_final = L_cam + delta_L (eq. 4.29), in linear sRGB, clamped and encoded back to 8-bit sRGB.
[[nodiscard]] ColorImage composite(const ColorImage& camera, const RadianceImage& delta);

/// The virtual-object mask implied by the inputs: L_rv(p) != L_r(p).
[[nodiscard]] Mask virtual_mask(const RadianceImage& real, const RadianceImage& real_virtual);

}  // namespace relight::colormap
