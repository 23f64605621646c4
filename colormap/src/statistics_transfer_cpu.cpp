// CPU reference of the statistics-based mapping (definition in statistics_transfer.h).
#include <cmath>
#include <string>

#include "relight/colormap/statistics_transfer.h"
#include "relight/core/error.h"

namespace relight::colormap {

namespace {

void require_same_shape(const RadianceImage& real, const RadianceImage& real_virtual, const ColorImage* camera) {
  const bool same = real.same_shape(real_virtual) && (camera == nullptr || real.same_shape(*camera));
  if (!same) {
    throw Error("colormap: L_r, L_rv and the camera image must have the same size (L_r is " +
                std::to_string(real.width()) + "x" + std::to_string(real.height()) + ")");
  }
}

bool finite(const Float3& c) { return std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z); }

LabStatistics finish(std::int64_t count, const std::array<double, 3>& sum, const std::array<double, 3>& sum_sq) {
  LabStatistics statistics;
  statistics.count = count;
  if (count == 0) return statistics;
  const double n = static_cast<double>(count);
  for (int k = 0; k < 3; ++k) {
    const double mean = sum[k] / n;
    statistics.mean[k] = mean;
    statistics.stddev[k] = std::sqrt(std::max(0.0, sum_sq[k] / n - mean * mean));
  }
  return statistics;
}

void accumulate(std::array<double, 3>& sum, std::array<double, 3>& sum_sq, const LabPixel& lab) {
  const double v[3] = {lab.x, lab.y, lab.z};
  for (int k = 0; k < 3; ++k) {
    sum[k] += v[k];
    sum_sq[k] += v[k] * v[k];
  }
}

}  // namespace

LabSums& LabSums::operator+=(const LabSums& other) {
  count += other.count;
  for (int k = 0; k < 3; ++k) {
    source_sum[k] += other.source_sum[k];
    source_sum_sq[k] += other.source_sum_sq[k];
    target_sum[k] += other.target_sum[k];
    target_sum_sq[k] += other.target_sum_sq[k];
  }
  return *this;
}

TransferStatistics statistics_from_sums(const LabSums& sums) {
  return {finish(sums.count, sums.source_sum, sums.source_sum_sq),
          finish(sums.count, sums.target_sum, sums.target_sum_sq)};
}

bool is_statistics_pixel(const Float3& real, const Float3& real_virtual, const Rgb8& camera, const ToneMap& tm) {
  if (!finite(real) || !(real == real_virtual)) return false;
  if (camera.r == 0 && camera.g == 0 && camera.b == 0) return false;
  const Float3 mapped = tone_map(real, tm);
  return mapped.x > 0.f || mapped.y > 0.f || mapped.z > 0.f;
}

TransferStatistics masked_lab_statistics(const RadianceImage& real, const RadianceImage& real_virtual,
                                         const ColorImage& camera, const ToneMap& tm) {
  require_same_shape(real, real_virtual, &camera);
  LabSums sums;
  for (std::size_t i = 0; i < real.size(); ++i) {
    const Float3& r = real.pixels()[i];
    const Rgb8& c = camera.pixels()[i];
    if (!is_statistics_pixel(r, real_virtual.pixels()[i], c, tm)) continue;
    ++sums.count;
    accumulate(sums.source_sum, sums.source_sum_sq, linear_srgb_to_lab(tone_map(r, tm)));
    accumulate(sums.target_sum, sums.target_sum_sq, linear_srgb_to_lab(decode_srgb8(c)));
  }
  return statistics_from_sums(sums);
}

ReinhardTransfer ReinhardTransfer::from(const TransferStatistics& statistics) {
  ReinhardTransfer transfer;
  if (statistics.source.count == 0) return transfer;
  for (int k = 0; k < 3; ++k) {
    const double sigma_s = statistics.source.stddev[k];
    const double scale = sigma_s > 1e-6 ? statistics.target.stddev[k] / sigma_s : 1.0;
    transfer.scale[k] = static_cast<float>(scale);
    transfer.offset[k] = static_cast<float>(statistics.target.mean[k] - scale * statistics.source.mean[k]);
  }
  return transfer;
}

Float3 map_statistics(const Float3& radiance, const ReinhardTransfer& transfer, const ToneMap& tm) {
  return lab_to_linear_srgb(transfer.apply(linear_srgb_to_lab(tone_map(radiance, tm))));
}

void statistics_delta(const RadianceImage& real, const RadianceImage& real_virtual, const ReinhardTransfer& transfer,
                      const ToneMap& tm, RadianceImage& delta) {
  require_same_shape(real, real_virtual, nullptr);
  delta.resize(real.width(), real.height());
  for (std::size_t i = 0; i < real.size(); ++i) {
    const Float3& r = real.pixels()[i];
    const Float3& rv = real_virtual.pixels()[i];
    // Equal inputs give equal tau_st: skip the two Lab round trips on the (vast) real part.
    delta.pixels()[i] = r == rv ? Float3{} : map_statistics(rv, transfer, tm) - map_statistics(r, transfer, tm);
  }
}

ReinhardTransfer statistics_color_map(const RadianceImage& real, const RadianceImage& real_virtual,
                                      const ColorImage& camera, const ToneMap& tm, RadianceImage& delta) {
  const ReinhardTransfer transfer = ReinhardTransfer::from(masked_lab_statistics(real, real_virtual, camera, tm));
  statistics_delta(real, real_virtual, transfer, tm, delta);
  return transfer;
}

ColorImage composite(const ColorImage& camera, const RadianceImage& delta) {
  if (!camera.same_shape(delta)) throw Error("colormap: the camera image and delta_L must have the same size");
  ColorImage mapped(camera.width(), camera.height());
  for (std::size_t i = 0; i < camera.size(); ++i) {
    const Float3& d = delta.pixels()[i];
    // A zero delta keeps the camera pixel bit for bit (no decode/encode rounding).
    mapped.pixels()[i] = d == Float3{} ? camera.pixels()[i] : encode_srgb8(decode_srgb8(camera.pixels()[i]) + d);
  }
  return mapped;
}

Mask virtual_mask(const RadianceImage& real, const RadianceImage& real_virtual) {
  require_same_shape(real, real_virtual, nullptr);
  Mask mask(real.width(), real.height());
  for (std::size_t i = 0; i < real.size(); ++i) mask.pixels()[i] = real.pixels()[i] == real_virtual.pixels()[i] ? 0 : 1;
  return mask;
}

}  // namespace relight::colormap
