// Statistics-based mapping on the CPU (definition in statistics_transfer.h).
//
// Speed (640x480 in well under the 2 ms goal on two cores): the reduction runs row-parallel with
// one partial LabSums per row, added up in row order afterwards, so the result does not depend
// on the thread count or schedule. Per row it works in three passes so that the middle one, the
// expensive cube roots, is a plain loop over float arrays that the compiler vectorises:
//   1. gather: the valid pixels' XYZ of TM(L_r) and of L_cam, compacted (the camera through
//      per-channel tables of 8-bit sRGB -> linear -> XYZ column, no pow per pixel);
//   2. XYZ -> Lab in place with fast_cbrt (color_space.h) instead of std::cbrt;
//   3. sums and sums of squares in double, as before.
// delta_L only has work on the virtual object, so it stays a per-pixel loop (row-parallel), with
// fast_cbrt in the Lab conversion as well.
#include <array>
#include <cmath>
#include <span>
#include <string>
#include <vector>

#include "relight/colormap/statistics_transfer.h"
#include "relight/core/error.h"
#include "relight/core/parallel.h"

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

/// XYZ contribution of each 8-bit camera channel: column k of kLinearSrgbToXyzE times the
/// decoded value. Summing the three entries multiplies and adds in the same order as
/// linear_srgb_to_xyz(decode_srgb8(c)), so the result is the same float.
using CameraXyzTable = std::array<std::array<Float3, 256>, 3>;

const CameraXyzTable& camera_xyz_table() {
  static const CameraXyzTable table = [] {
    CameraXyzTable t{};
    for (std::size_t k = 0; k < 3; ++k) {
      for (std::size_t v = 0; v < 256; ++v) {
        const float linear = srgb8_to_linear(static_cast<std::uint8_t>(v));
        t[k][v] = {kLinearSrgbToXyzE[0][k] * linear, kLinearSrgbToXyzE[1][k] * linear,
                   kLinearSrgbToXyzE[2][k] * linear};
      }
    }
    return t;
  }();
  return table;
}

/// linear_srgb_to_xyz, inlined into the gather loop (same products and order).
Float3 source_xyz(const Float3& rgb) {
  const auto& m = kLinearSrgbToXyzE;
  return {m[0][0] * rgb.x + m[0][1] * rgb.y + m[0][2] * rgb.z, m[1][0] * rgb.x + m[1][1] * rgb.y + m[1][2] * rgb.z,
          m[2][0] * rgb.x + m[2][1] * rgb.y + m[2][2] * rgb.z};
}

Float3 camera_xyz(const CameraXyzTable& table, const Rgb8& c) {
  return table[0][c.r] + table[1][c.g] + table[2][c.b];
}

/// Struct-of-arrays buffers of one row's valid pixels: X, Y, Z (then L, a, b in place) of the
/// source f(TM(L_r)) and the target f(L_cam).
struct RowChannels {
  explicit RowChannels(int width) {
    for (auto& channel : values) channel.resize(static_cast<std::size_t>(width));
  }
  std::array<std::vector<float>, 6> values;  // source X, Y, Z, target X, Y, Z
  int count = 0;

  void push(const Float3& source, const Float3& target) {
    const auto i = static_cast<std::size_t>(count++);
    values[0][i] = source.x, values[1][i] = source.y, values[2][i] = source.z;
    values[3][i] = target.x, values[4][i] = target.y, values[5][i] = target.z;
  }
};

/// linear_srgb_to_lab with fast_cbrt.
LabPixel lab_fast(const Float3& rgb) {
  const Float3 xyz = source_xyz(rgb);
  const float gx = lab_g_fast(xyz.x), gy = lab_g_fast(xyz.y), gz = lab_g_fast(xyz.z);
  return {116.f * gy - 16.f, 500.f * (gx - gy), 200.f * (gy - gz)};
}

/// map_statistics with fast_cbrt (the way back, lab_to_linear_srgb, only cubes).
Float3 map_statistics_fast(const Float3& radiance, const ReinhardTransfer& transfer, const ToneMap& tm) {
  return lab_to_linear_srgb(transfer.apply(lab_fast(tone_map(radiance, tm))));
}

/// Pass 1: the valid-pixel rule of is_statistics_pixel, and both XYZ colours of the valid ones.
void gather_valid(std::span<const Float3> real, std::span<const Float3> real_virtual, std::span<const Rgb8> camera,
                  const ToneMap& tm, RowChannels& row) {
  const CameraXyzTable& table = camera_xyz_table();
  row.count = 0;
  for (std::size_t i = 0; i < real.size(); ++i) {
    const Float3& r = real[i];
    const Rgb8& c = camera[i];
    if (!finite(r) || !(r == real_virtual[i]) || (c.r == 0 && c.g == 0 && c.b == 0)) continue;
    const Float3 mapped = tone_map(r, tm);
    if (!(mapped.x > 0.f || mapped.y > 0.f || mapped.z > 0.f)) continue;
    row.push(source_xyz(mapped), camera_xyz(table, c));
  }
}

/// Pass 2: XYZ -> Lab in place over `count` values (xyz_to_lab with lab_g_fast). Also built for
/// AVX2, picked at load time where the CPU has it (8 floats a step instead of SSE2's 4, about
/// 14% less CPU time per frame here); "avx2" does not enable FMA, so both versions round alike.
__attribute__((target_clones("avx2", "default"))) void xyz_to_lab_in_place(float* x, float* y, float* z, int count) {
  for (int i = 0; i < count; ++i) {
    const float gx = lab_g_fast(x[i]), gy = lab_g_fast(y[i]), gz = lab_g_fast(z[i]);
    x[i] = 116.f * gy - 16.f;
    y[i] = 500.f * (gx - gy);
    z[i] = 200.f * (gy - gz);
  }
}

/// Pass 3: sums and sums of squares of the six Lab channels, in double like the reference. One
/// loop with twelve independent accumulators: a loop per channel waits on the latency of each
/// add (one chain), and took longer than the cube roots.
LabSums row_sums(RowChannels& row) {
  auto& v = row.values;
  xyz_to_lab_in_place(v[0].data(), v[1].data(), v[2].data(), row.count);
  xyz_to_lab_in_place(v[3].data(), v[4].data(), v[5].data(), row.count);
  std::array<double, 6> sum{}, sum_sq{};
  for (std::size_t i = 0; i < static_cast<std::size_t>(row.count); ++i) {
    for (std::size_t k = 0; k < 6; ++k) {
      const double value = v[k][i];
      sum[k] += value;
      sum_sq[k] += value * value;
    }
  }
  LabSums sums;
  sums.count = row.count;
  for (std::size_t k = 0; k < 3; ++k) {
    sums.source_sum[k] = sum[k], sums.source_sum_sq[k] = sum_sq[k];
    sums.target_sum[k] = sum[k + 3], sums.target_sum_sq[k] = sum_sq[k + 3];
  }
  return sums;
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

LabSums masked_lab_sums(const RadianceImage& real, const RadianceImage& real_virtual, const ColorImage& camera,
                        const ToneMap& tm, int threads) {
  require_same_shape(real, real_virtual, &camera);
  std::vector<LabSums> per_row(static_cast<std::size_t>(real.height()));
  parallel_rows(real.height(), threads, [&](int begin, int end) {
    RowChannels channels(real.width());
    for (int y = begin; y < end; ++y) {
      gather_valid(real.row(y), real_virtual.row(y), camera.row(y), tm, channels);
      per_row[static_cast<std::size_t>(y)] = row_sums(channels);
    }
  });
  LabSums sums;
  for (const LabSums& row : per_row) sums += row;  // fixed order: deterministic
  return sums;
}

TransferStatistics masked_lab_statistics(const RadianceImage& real, const RadianceImage& real_virtual,
                                         const ColorImage& camera, const ToneMap& tm, int threads) {
  return statistics_from_sums(masked_lab_sums(real, real_virtual, camera, tm, threads));
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
                      const ToneMap& tm, RadianceImage& delta, int threads) {
  require_same_shape(real, real_virtual, nullptr);
  delta.resize(real.width(), real.height());
  parallel_for_each_row(real.height(), threads, [&](int y) {
    const auto r = real.row(y), rv = real_virtual.row(y);
    const auto out = delta.row(y);
    for (std::size_t i = 0; i < r.size(); ++i) {
      // Equal inputs give equal tau_st: skip the two Lab round trips on the (vast) real part.
      out[i] = r[i] == rv[i] ? Float3{}
                             : map_statistics_fast(rv[i], transfer, tm) - map_statistics_fast(r[i], transfer, tm);
    }
  }, 16);
}

ReinhardTransfer statistics_color_map(const RadianceImage& real, const RadianceImage& real_virtual,
                                      const ColorImage& camera, const ToneMap& tm, RadianceImage& delta,
                                      int threads) {
  const ReinhardTransfer transfer =
      ReinhardTransfer::from(masked_lab_statistics(real, real_virtual, camera, tm, threads));
  statistics_delta(real, real_virtual, transfer, tm, delta, threads);
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
