// Statistics-based mapping on the CPU (definition in statistics_transfer.h).
//
// Speed: the reduction runs row-parallel with one partial LabSums per row, added up in row order
// afterwards, so the result does not depend on the thread count or schedule. Each row goes in
// blocks of 64 pixels whose struct-of-arrays buffers stay in L1:
//   1. load (scalar): L_r and L_rv de-interleaved, the camera decoded through a 256-entry table;
//   2. source: the valid-pixel rule as lane masks, then TM(L_r) -> Lab with fast_cbrt
//      (color_space.h), summed;
//   3. target: the camera's Lab over the same pixels, summed.
// Passes 2 and 3 are written on eight-float vectors (GCC's vector extension; AVX2 or SSE2):
// written as scalar loops, the valid-pixel test and the reduction did not vectorise. Sums go
// into float lanes per block and into double per row.
// The reduction also notes each row's span of virtual pixels (L_rv != L_r) and, for
// statistics_color_map, writes the zero rows of delta_L while it is there; the per-pixel
// tau_st round trips then run (vectorised, fast_cbrt) only on those spans.
//
// Measured (640x480, two cores, colormap/stats_cpu): 2.2-3.0 ms a frame, from 4.7-6.2 ms.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "relight/colormap/statistics_transfer.h"
#include "relight/core/cpu_dispatch.h"
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

/// 8-bit sRGB -> linear (srgb8_to_linear) as a table the loops index directly.
using Srgb8Table = std::array<float, 256>;
const Srgb8Table& srgb8_table() {
  static const Srgb8Table table = [] {
    Srgb8Table t{};
    for (std::size_t v = 0; v < t.size(); ++v) t[v] = srgb8_to_linear(static_cast<std::uint8_t>(v));
    return t;
  }();
  return table;
}

/// Pixels per block: the block's 10 rows of 64 floats stay in L1.
constexpr int kBlock = 64;
/// Eight floats: one AVX2 register, two SSE2 registers in the default build (GCC's vector
/// extension lowers the type to what the target has).
constexpr int kLanes = 8;
using Vec = float __attribute__((vector_size(4 * kLanes)));
using IntVec = std::int32_t __attribute__((vector_size(4 * kLanes)));

/// Pixels [begin, end) of a row hold the first and the last with L_rv != L_r (empty: none).
struct VirtualSpan {
  int begin = 0, end = 0;
  [[nodiscard]] bool empty() const { return begin >= end; }
  /// Adds the pixels of `block` (starting at pixel `offset` of the row, `count` of them) that
  /// differ between L_r and L_rv.
  template <class Block>
  void extend(const Block& block, int offset, int count) {
    for (int i = 0; i < count; ++i) {
      const bool same = block.real[0][i] == block.real_virtual[0][i] && block.real[1][i] == block.real_virtual[1][i] &&
                        block.real[2][i] == block.real_virtual[2][i];
      if (same) continue;
      if (empty()) begin = offset + i;
      end = offset + i + 1;
    }
  }
};

/// One block of pixels in struct-of-arrays form (channel-major L_r, L_rv and the decoded
/// camera) and the valid-pixel weights, 1 or 0.
struct alignas(32) PixelBlock {
  float real[3][kBlock];
  float real_virtual[3][kBlock];
  float camera[3][kBlock];
  float weight[kBlock];
};

/// Pass 1, the only scalar one: L_r and L_rv de-interleaved, the camera decoded through the
/// table. A short last block is padded with black pixels, which the valid-pixel rule drops.
[[gnu::always_inline]] inline void load_block(const Float3* __restrict real, const Float3* __restrict real_virtual,
                                              const Rgb8* __restrict camera, int count, const Srgb8Table& decode,
                                              PixelBlock& __restrict block) {
  for (int i = 0; i < count; ++i) {
    block.real[0][i] = real[i].x, block.real[1][i] = real[i].y, block.real[2][i] = real[i].z;
    block.real_virtual[0][i] = real_virtual[i].x, block.real_virtual[1][i] = real_virtual[i].y;
    block.real_virtual[2][i] = real_virtual[i].z;
    block.camera[0][i] = decode[camera[i].r], block.camera[1][i] = decode[camera[i].g];
    block.camera[2][i] = decode[camera[i].b];
  }
  for (int i = count; i < kBlock; ++i) {
    for (int k = 0; k < 3; ++k) block.real[k][i] = block.real_virtual[k][i] = block.camera[k][i] = 0.f;
  }
}

[[gnu::always_inline]] inline Vec load(const float* values) {
  Vec v;
  std::memcpy(&v, values, sizeof v);
  return v;
}

[[gnu::always_inline]] inline Vec splat(float value) { return Vec{} + value; }

/// fast_cbrt (color_space.h) on eight lanes, the same operations in the same order.
[[gnu::always_inline]] inline Vec fast_cbrt(Vec x) {
  constexpr std::int32_t kMagic = 0x54a2fa8c;
  const auto bits = std::bit_cast<IntVec>(x);
  const Vec third_bits = __builtin_convertvector(bits, Vec) * (1.f / 3.f);
  Vec y = std::bit_cast<Vec>(kMagic - __builtin_convertvector(third_bits, IntVec));
  const Vec third_x = x * (1.f / 3.f);
  y = y * (4.f / 3.f - third_x * y * y * y);
  y = y * (4.f / 3.f - third_x * y * y * y);
  y = y * (4.f / 3.f - third_x * y * y * y);
  return x * y * y;
}

/// lab_g_fast on eight lanes.
[[gnu::always_inline]] inline Vec lab_g(Vec t) {
  const Vec cube_root = fast_cbrt(t > kLabDeltaCubed ? t : splat(kLabDeltaCubed));
  return t > kLabDeltaCubed ? cube_root : t * kLabLinearSlope + 4.f / 29.f;
}

struct ToneMapped {
  Vec r, g, b;
};

/// tone_map (tone_map.h) on eight lanes, the same operations in the same order.
[[gnu::always_inline]] inline ToneMapped tone_map(Vec r, Vec g, Vec b, const ToneMap& tm) {
  const Vec sr = r * tm.exposure, sg = g * tm.exposure, sb = b * tm.exposure;
  const Vec rg = sr > sg ? sr : sg;
  const Vec y = compression(tm) * (rg > sb ? rg : sb);
  const Vec l = y > 0.f ? y : Vec{};
  const Vec f = (1.f + l * tm.inverse_white_squared) / (1.f + l);
  const auto clamp = [](Vec v) {
    const Vec low = v > 0.f ? v : Vec{};
    return low < 1.f ? low : splat(1.f);
  };
  return {clamp(sr * f), clamp(sg * f), clamp(sb * f)};
}

struct LabVec {
  Vec l, a, b;
};

/// linear_srgb_to_lab on eight lanes.
[[gnu::always_inline]] inline LabVec rgb_to_lab(Vec r, Vec g, Vec b) {
  const auto& m = kLinearSrgbToXyzE;
  const Vec gx = lab_g(m[0][0] * r + m[0][1] * g + m[0][2] * b);
  const Vec gy = lab_g(m[1][0] * r + m[1][1] * g + m[1][2] * b);
  const Vec gz = lab_g(m[2][0] * r + m[2][1] * g + m[2][2] * b);
  return {116.f * gy - 16.f, 500.f * (gx - gy), 200.f * (gy - gz)};
}

/// Sums and sums of squares of L, a, b over a block, in float lanes of 8 values each: float's
/// 6e-8 relative rounding per add stays far below the 1e-4 Lab units the statistics are held
/// to, and the lanes go into double once per block.
struct LabBlockSums {
  Vec sum[3]{}, sum_sq[3]{};

  [[gnu::always_inline]] void add(const LabVec& lab, Vec valid) {
    const Vec values[3] = {lab.l, lab.a, lab.b};
    for (int k = 0; k < 3; ++k) {
      // Selected, not multiplied: an invalid pixel's Lab is 0 only up to rounding.
      const Vec v = valid != 0.f ? values[k] : Vec{};
      sum[k] += v;
      sum_sq[k] += v * v;
    }
  }
};

/// Pass 2: the valid-pixel rule of is_statistics_pixel as lane masks, into block.weight; and
/// the Lab sums of the source TM(L_r). Invalid pixels are zeroed before the conversion, so that
/// NaN or infinite radiance cannot reach the sums. A camera pixel is black exactly when its
/// decoded channels sum to 0. Returns the number of pixels with L_rv != L_r.
[[gnu::always_inline]] inline int source_sums(const ToneMap& tm, PixelBlock& block, LabBlockSums& sums) {
  IntVec virtual_lanes{};
  for (int i = 0; i < kBlock; i += kLanes) {
    const Vec r = load(&block.real[0][i]), g = load(&block.real[1][i]), b = load(&block.real[2][i]);
    const IntVec same = (r == load(&block.real_virtual[0][i])) & (g == load(&block.real_virtual[1][i])) &
                        (b == load(&block.real_virtual[2][i]));
    const auto finite = [](Vec v) { return (v <= std::numeric_limits<float>::max()) & (v >= -std::numeric_limits<float>::max()); };
    const ToneMapped mapped = tone_map(r, g, b, tm);
    const Vec mapped_r = mapped.r, mapped_g = mapped.g, mapped_b = mapped.b;
    const Vec camera_sum = load(&block.camera[0][i]) + load(&block.camera[1][i]) + load(&block.camera[2][i]);
    const IntVec valid = same & finite(r) & finite(g) & finite(b) & (camera_sum > 0.f) &
                         ((mapped_r > 0.f) | (mapped_g > 0.f) | (mapped_b > 0.f));
    virtual_lanes += same + 1;  // same is -1 (true) or 0: adds 1 where L_rv != L_r
    const Vec weight = valid ? splat(1.f) : Vec{};
    std::memcpy(&block.weight[i], &weight, sizeof weight);
    sums.add(rgb_to_lab(valid ? mapped_r : Vec{}, valid ? mapped_g : Vec{}, valid ? mapped_b : Vec{}), weight);
  }
  int virtual_pixels = 0;
  for (int j = 0; j < kLanes; ++j) virtual_pixels += virtual_lanes[j];
  return virtual_pixels;
}

/// Pass 3: the Lab sums of the camera image f(L_cam) over the valid pixels of pass 2.
[[gnu::always_inline]] inline void target_sums(const PixelBlock& block, LabBlockSums& sums) {
  for (int i = 0; i < kBlock; i += kLanes) {
    const Vec weight = load(&block.weight[i]);
    const Vec r = load(&block.camera[0][i]), g = load(&block.camera[1][i]), b = load(&block.camera[2][i]);
    sums.add(rgb_to_lab(r, g, b), weight);
  }
}

/// Running sums of one row: the count, and per channel (source L, a, b, target L, a, b) the sum
/// and the sum of squares, each in kLanes double lanes.
struct RowAccumulator {
  double count[kLanes]{};
  double sum[6][kLanes]{};
  double sum_sq[6][kLanes]{};

  [[gnu::always_inline]] void add(const PixelBlock& block, const LabBlockSums& source, const LabBlockSums& target) {
    for (int k = 0; k < 3; ++k) {
      for (int j = 0; j < kLanes; ++j) {
        sum[k][j] += source.sum[k][j], sum_sq[k][j] += source.sum_sq[k][j];
        sum[k + 3][j] += target.sum[k][j], sum_sq[k + 3][j] += target.sum_sq[k][j];
      }
    }
    for (int i = 0; i < kBlock; i += kLanes) {
      for (int j = 0; j < kLanes; ++j) count[j] += block.weight[i + j];
    }
  }

  [[nodiscard]] LabSums total() const {
    const auto lanes = [](const double (&lane)[kLanes]) {
      double total = 0.0;
      for (const double value : lane) total += value;
      return total;
    };
    LabSums sums;
    sums.count = static_cast<std::int64_t>(lanes(count));
    for (std::size_t k = 0; k < 3; ++k) {
      sums.source_sum[k] = lanes(sum[k]), sums.source_sum_sq[k] = lanes(sum_sq[k]);
      sums.target_sum[k] = lanes(sum[k + 3]), sums.target_sum_sq[k] = lanes(sum_sq[k + 3]);
    }
    return sums;
  }
};

/// The passes over one row. Also built for AVX2, picked at load time where the CPU has it;
/// "avx2" does not enable FMA, so both versions round alike. Returns whether the row has pixels
/// with L_rv != L_r.
RELIGHT_AVX2_CLONES VirtualSpan row_sums(std::span<const Float3> real, std::span<const Float3> real_virtual,
                                         std::span<const Rgb8> camera, const ToneMap& tm, LabSums& sums) {
  const Srgb8Table& decode = srgb8_table();
  RowAccumulator accumulator;
  PixelBlock block;
  VirtualSpan span;
  const int width = static_cast<int>(real.size());
  for (int begin = 0; begin < width; begin += kBlock) {
    const auto at = static_cast<std::size_t>(begin);
    const int count = std::min(kBlock, width - begin);
    load_block(&real[at], &real_virtual[at], &camera[at], count, decode, block);
    LabBlockSums source, target;
    if (source_sums(tm, block, source) > 0) span.extend(block, begin, count);
    target_sums(block, target);
    accumulator.add(block, source, target);
  }
  sums = accumulator.total();
  return span;
}

/// masked_lab_sums, also noting the span of virtual pixels of each row. With `delta`, also
/// writes its zero rows, those without virtual pixels, while the row is at hand: the zeros are most of delta_L, and their
/// memory traffic hides behind the reduction's arithmetic instead of taking a pass of its own.
LabSums reduce_rows(const RadianceImage& real, const RadianceImage& real_virtual, const ColorImage& camera,
                    const ToneMap& tm, int threads, std::vector<VirtualSpan>& spans, RadianceImage* delta) {
  require_same_shape(real, real_virtual, &camera);
  std::vector<LabSums> per_row(static_cast<std::size_t>(real.height()));
  spans.assign(per_row.size(), {});
  if (delta != nullptr) delta->resize(real.width(), real.height());
  parallel_for_each_row(real.height(), threads, [&](int y) {
    const auto row = static_cast<std::size_t>(y);
    spans[row] = row_sums(real.row(y), real_virtual.row(y), camera.row(y), tm, per_row[row]);
    if (delta != nullptr && spans[row].empty()) std::ranges::fill(delta->row(y), Float3{});
  }, 16);
  LabSums sums;
  for (const LabSums& row : per_row) sums += row;  // fixed order: deterministic
  return sums;
}

/// tau_st of eq. 4.30 in place on three channel rows of linear radiance (map_statistics with
/// fast_cbrt, vectorised); the Lab curve's inverse multiplies by 1 / slope instead of dividing.
[[gnu::always_inline]] inline void map_statistics_in_place(float (&r)[kBlock], float (&g)[kBlock],
                                                           float (&b)[kBlock], const ReinhardTransfer& transfer,
                                                           const ToneMap& tm) {
  const auto& to_xyz = kLinearSrgbToXyzE;
  const auto& to_rgb = kXyzEToLinearSrgb;
  const auto& [scale, offset] = transfer;
  const auto g_inverse = [](float u) { return u > kLabDelta ? u * u * u : (u - 4.f / 29.f) * (1.f / kLabLinearSlope); };
  for (int i = 0; i < kBlock; ++i) {
    const auto [red, green, blue] = tone_map(Float3{r[i], g[i], b[i]}, tm);
    const float gx = lab_g_fast(to_xyz[0][0] * red + to_xyz[0][1] * green + to_xyz[0][2] * blue);
    const float gy = lab_g_fast(to_xyz[1][0] * red + to_xyz[1][1] * green + to_xyz[1][2] * blue);
    const float gz = lab_g_fast(to_xyz[2][0] * red + to_xyz[2][1] * green + to_xyz[2][2] * blue);
    const float lightness = scale[0] * (116.f * gy - 16.f) + offset[0];
    const float a = scale[1] * (500.f * (gx - gy)) + offset[1];
    const float b_star = scale[2] * (200.f * (gy - gz)) + offset[2];
    const float u = (lightness + 16.f) / 116.f;
    const float x = g_inverse(u + a / 500.f), y = g_inverse(u), z = g_inverse(u - b_star / 200.f);
    r[i] = to_rgb[0][0] * x + to_rgb[0][1] * y + to_rgb[0][2] * z;
    g[i] = to_rgb[1][0] * x + to_rgb[1][1] * y + to_rgb[1][2] * z;
    b[i] = to_rgb[2][0] * x + to_rgb[2][1] * y + to_rgb[2][2] * z;
  }
}

/// delta_L on pixels [begin, end) of a row, in blocks: tau_st(L_rv) - tau_st(L_r), exactly 0 where
/// L_rv == L_r. Built for AVX2 as well, like row_sums.
RELIGHT_AVX2_CLONES void delta_span(const Float3* real, const Float3* real_virtual, Float3* delta, int count,
                                    const ReinhardTransfer& transfer, const ToneMap& tm) {
  PixelBlock block;
  for (int begin = 0; begin < count; begin += kBlock) {
    const int n = std::min(kBlock, count - begin);
    for (int i = 0; i < n; ++i) {
      const Float3& r = real[begin + i];
      const Float3& rv = real_virtual[begin + i];
      block.real[0][i] = r.x, block.real[1][i] = r.y, block.real[2][i] = r.z;
      block.real_virtual[0][i] = rv.x, block.real_virtual[1][i] = rv.y, block.real_virtual[2][i] = rv.z;
    }
    map_statistics_in_place(block.real[0], block.real[1], block.real[2], transfer, tm);
    map_statistics_in_place(block.real_virtual[0], block.real_virtual[1], block.real_virtual[2], transfer, tm);
    for (int i = 0; i < n; ++i) {
      const bool same = real[begin + i] == real_virtual[begin + i];
      delta[begin + i] = same ? Float3{} : Float3{block.real_virtual[0][i] - block.real[0][i],
                                                  block.real_virtual[1][i] - block.real[1][i],
                                                  block.real_virtual[2][i] - block.real[2][i]};
    }
  }
}

/// The span of the pixels of a row with L_rv != L_r.
VirtualSpan find_virtual_span(std::span<const Float3> real, std::span<const Float3> real_virtual) {
  VirtualSpan span;
  for (std::size_t i = 0; i < real.size(); ++i) {
    if (real[i] == real_virtual[i]) continue;
    if (span.empty()) span.begin = static_cast<int>(i);
    span.end = static_cast<int>(i) + 1;
  }
  return span;
}

/// delta_L of one row: tau_st(L_rv) - tau_st(L_r) on `span` (which must cover every pixel with
/// L_rv != L_r), zero elsewhere.
void delta_row(std::span<const Float3> real, std::span<const Float3> real_virtual, VirtualSpan span,
               const ReinhardTransfer& transfer, const ToneMap& tm, std::span<Float3> delta) {
  std::ranges::fill(delta, Float3{});
  if (span.empty()) return;
  const auto at = static_cast<std::size_t>(span.begin);
  delta_span(&real[at], &real_virtual[at], &delta[at], span.end - span.begin, transfer, tm);
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
  std::vector<VirtualSpan> spans;
  return reduce_rows(real, real_virtual, camera, tm, threads, spans, nullptr);
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
    delta_row(r, rv, find_virtual_span(r, rv), transfer, tm, delta.row(y));
  }, 16);
}

ReinhardTransfer statistics_color_map(const RadianceImage& real, const RadianceImage& real_virtual,
                                      const ColorImage& camera, const ToneMap& tm, RadianceImage& delta,
                                      int threads) {
  std::vector<VirtualSpan> spans;
  const LabSums sums = reduce_rows(real, real_virtual, camera, tm, threads, spans, &delta);
  const ReinhardTransfer transfer = ReinhardTransfer::from(statistics_from_sums(sums));
  // The reduction wrote the zero rows; the rows of the virtual object are few.
  std::vector<int> virtual_rows;
  for (int y = 0; y < real.height(); ++y) {
    if (!spans[static_cast<std::size_t>(y)].empty()) virtual_rows.push_back(y);
  }
  parallel_for_each_row(static_cast<int>(virtual_rows.size()), threads, [&](int i) {
    const int y = virtual_rows[static_cast<std::size_t>(i)];
    delta_row(real.row(y), real_virtual.row(y), spans[static_cast<std::size_t>(y)], transfer, tm, delta.row(y));
  }, 4);
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
