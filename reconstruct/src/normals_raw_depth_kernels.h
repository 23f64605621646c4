#pragma once
// Internal to method 1 on the CPU (normals_raw_depth_cpu.cpp, normals_raw_depth_avx2.cpp; the
// definition is in normals_raw_depth.h): the per-frame constants, the pass-1 pyramid as
// structure of arrays, and the per-pixel arithmetic of the scalar loops.
//
// The AVX2 loops perform the same IEEE operations in the same order as these scalar functions,
// so both give bit-identical maps (the tests compare them). That holds because nothing is
// contracted into fused multiply-adds: neither the x86-64 baseline nor target("avx2") enables
// FMA, so the compiler has no FMA to contract into, whatever -ffp-contract says.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "relight/core/pixel.h"

namespace relight::reconstruct::method1 {

/// Everything a row of pass 2 needs besides the images, in float as the loops use it.
struct Constants {
  int width = 0, height = 0, stride = 4;
  float inv_fx = 0, inv_fy = 0, cx = 0, cy = 0;  ///< back-projection, as positions_from_depth
  float fx = 0, fy = 0;                          ///< projection into the previous frame
  float max_jump_rel = 0.05f;
  bool centred = true;  ///< central differences where both sides continue
  float prev_from_current[12] = {};  ///< row-major 3x4 rigid transform
  float current_from_prev[9] = {};   ///< row-major 3x3 rotation
  float blend_base = 0.9f, disocclusion_m = 0.1f;
};

/// Shape of one pyramid level inside the concatenated arrays.
struct LevelShape {
  int width = 0, height = 0, offset = 0;
};

/// Pass 1's pyramid, or the rows of it that one block of level-0 rows covers: level l's texel
/// (r, c) is element levels[l].offset + r * width + c of x, y, z and curvature (each followed by
/// 8 padding elements; the coarser curvatures exist for normals_history_pyramid only).
struct Pyramid {
  std::vector<float> x, y, z, curvature;
  std::vector<LevelShape> levels;
};

/// Which history normal a pixel (row, col) of the previous frame contributes depends only on its
/// level-0 texel (row >> 1, col >> 1): the level comes from that texel's curvature, level l's
/// texel is (row >> 1 >> l, col >> 1 >> l), level 0's is the fallback. So pass 1 resolves it once
/// per level-0 texel, rotated into the current frame: element r * width + c (plus 8 padding
/// elements), NaN where the texel has no valid history normal.
struct History {
  std::vector<float> x, y, z;
  int width = 0;  ///< level-0 texels per row
};

/// Pass 2's inputs and outputs for one frame. In the fused mode positions and fresh normals are
/// computed from `depth` and the positions written to `positions_out`; in the blend-only mode
/// (depth == nullptr) they are read from `positions_in` and `normals`. Either way `normals`
/// receives the blended normals (holes still zero).
struct Pass2 {
  Constants k;
  const float* depth = nullptr;           ///< width x height, or null (blend-only)
  const float* x_scale = nullptr;         ///< (c − cx)·inv_fx for c in [−stride − 8, width + stride + 8)
  Float3* positions_out = nullptr;        ///< fused mode
  const Float3* positions_in = nullptr;   ///< blend-only mode
  Float3* normals = nullptr;
  const Float3* prev_positions = nullptr; ///< null: no history, no blend
  const History* history = nullptr;
  // Holes (a position but no normal), listed per row in column order with the value they had
  // before any fill, so that fills can be applied in any order: a fill reads a neighbouring hole
  // as it was (the definition fills from the blended map).
  std::uint32_t* hole_columns = nullptr;  ///< row r's holes start at r * width
  Float3* hole_values = nullptr;          ///< same indexing
  int* hole_counts = nullptr;             ///< per row
  std::uint32_t* hole_bits = nullptr;     ///< row r's bits start at r * hole_words
  int hole_words = 0;                     ///< (width + 31) / 32
};

inline bool valid_depth_value(float z) { return z > 0.f && z <= 3.4e38f; }  // positions_from_depth's test

/// Nearest integer, halves up: floor(x + 0.5), as the Vulkan shader rounds (for x ≥ 0, std::lround
/// except within an ulp below a half).
inline float round_half_up(float x) { return std::floor(x + 0.5f); }

inline Float3 normalized_or_zero(const Float3& v) {
  const float len = length(v);
  return len > 0.f ? (1.f / len) * v : Float3{};
}

inline float pow128(float x) {
  for (int i = 0; i < 7; ++i) x *= x;
  return x;
}

/// std::clamp(v, 0, 1) (NaN stays NaN).
inline float clamp01(float v) { return std::clamp(v, 0.f, 1.f); }

// ---- Pass 1 ----------------------------------------------------------------------------------

/// Level-0 texel (hr, hc) from the previous normals (width x height): mean of the pixel and its
/// 4-neighbourhood, curvature of eq. 4.1–4.3; stored in row out_row of `out`.
inline void level0_texel(const Float3* previous, int width, int height, int hr, int hc, Pyramid& out, int out_row) {
  const int r = 2 * hr, c = 2 * hc;
  const auto at = [&](int row, int col) -> Float3 {
    return row >= 0 && col >= 0 && row < height && col < width
               ? previous[static_cast<std::size_t>(row) * static_cast<std::size_t>(width) + static_cast<std::size_t>(col)]
               : Float3{};
  };
  const Float3 up = at(r - 1, c), down = at(r + 1, c), left = at(r, c - 1), right = at(r, c + 1);
  const auto cross_sum = [&](int row, int col) {  // missing ones are 0
    return at(row, col) + at(row - 1, col) + at(row + 1, col) + at(row, col - 1) + at(row, col + 1);
  };
  const Float3 n =
      normalized_or_zero(cross_sum(r, c) + cross_sum(r, c + 1) + cross_sum(r + 1, c) + cross_sum(r + 1, c + 1));
  const bool horizontal = is_valid_normal(left) && is_valid_normal(right);
  const bool vertical = is_valid_normal(up) && is_valid_normal(down);
  const float curv = horizontal && vertical ? std::min(dot(left, right), dot(up, down)) : 0.f;
  const std::size_t i = static_cast<std::size_t>(out_row) * static_cast<std::size_t>(out.levels[0].width) +
                        static_cast<std::size_t>(hc);
  out.x[i] = n.x;
  out.y[i] = n.y;
  out.z[i] = n.z;
  out.curvature[i] = pow128(clamp01(curv));
}

/// Texel (r, c) of `level` (>= 1): mean of the valid texels of its 2x2 block one level finer,
/// normal renormalised, curvature averaged.
inline void coarse_texel(Pyramid& p, int level, int r, int c) {
  const LevelShape& fine = p.levels[static_cast<std::size_t>(level) - 1];
  const LevelShape& coarse = p.levels[static_cast<std::size_t>(level)];
  Float3 sum;
  float curvature = 0.f;
  int count = 0;
  for (int dr = 0; dr < 2; ++dr) {
    for (int dc = 0; dc < 2; ++dc) {
      const int fr = 2 * r + dr, fc = 2 * c + dc;
      if (fr >= fine.height || fc >= fine.width) continue;
      const std::size_t i = static_cast<std::size_t>(fine.offset) + static_cast<std::size_t>(fr) * static_cast<std::size_t>(fine.width) + static_cast<std::size_t>(fc);
      const Float3 n{p.x[i], p.y[i], p.z[i]};
      if (!is_valid_normal(n)) continue;
      sum += n;
      curvature += p.curvature[i];
      ++count;
    }
  }
  const Float3 n = normalized_or_zero(sum);
  const std::size_t o = static_cast<std::size_t>(coarse.offset) + static_cast<std::size_t>(r) * static_cast<std::size_t>(coarse.width) + static_cast<std::size_t>(c);
  p.x[o] = n.x;
  p.y[o] = n.y;
  p.z[o] = n.z;
  p.curvature[o] = count > 0 ? curvature / static_cast<float>(count) : 0.f;
}

/// The pyramid level that the level-0 curvature selects (flat: coarse, edges: fine).
inline int chosen_level(float curvature, int max_level) {
  const float lf = round_half_up(curvature * static_cast<float>(max_level));
  return lf >= 0.f ? static_cast<int>(std::min(lf, static_cast<float>(max_level))) : 0;
}

/// The resolved history normal of level-0 texel (r, c) of `p` (see History), stored in row
/// out_row of `out`; needs every level's texels above it.
inline void resolve_texel(const Pyramid& p, const Constants& k, int r, int c, History& out, int out_row) {
  const auto texel = [&p](int level, int row, int col) {
    const LevelShape& shape = p.levels[static_cast<std::size_t>(level)];
    const auto i = static_cast<std::size_t>(shape.offset + (row >> level) * shape.width + (col >> level));
    return Float3{p.x[i], p.y[i], p.z[i]};
  };
  const auto i0 = static_cast<std::size_t>(r * p.levels[0].width + c);
  const auto o = static_cast<std::size_t>(out_row * out.width + c);
  const int level = chosen_level(p.curvature[i0], static_cast<int>(p.levels.size()) - 1);
  Float3 h = texel(level, r, c);
  if (!is_valid_normal(h)) h = texel(0, r, c);
  const float* m = k.current_from_prev;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const bool valid = is_valid_normal(h);
  out.x[o] = valid ? m[0] * h.x + m[1] * h.y + m[2] * h.z : nan;
  out.y[o] = valid ? m[3] * h.x + m[4] * h.y + m[5] * h.z : nan;
  out.z[o] = valid ? m[6] * h.x + m[7] * h.y + m[8] * h.z : nan;
}

// ---- Pass 2 ----------------------------------------------------------------------------------

inline Float3 cross3(const Float3& a, const Float3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

/// Difference along one axis (normals_from_positions): central if asked for and both sides
/// continue the surface, else forward if it does, else backward, else zero (which makes the cross
/// product zero: no normal).
inline Float3 axis_difference(const Float3& centre, const Float3& forward, const Float3& backward, float limit,
                              bool centred) {
  const bool forward_ok = forward.z > 0.f && std::fabs(forward.z - centre.z) <= limit;
  const bool backward_ok = backward.z > 0.f && std::fabs(backward.z - centre.z) <= limit;
  if (forward_ok && backward_ok && centred) return forward - backward;
  if (forward_ok) return forward - centre;
  if (backward_ok) return centre - backward;
  return {};
}

/// Stride-s cross-product normal from the positions of the pixel and its four neighbours (z = 0
/// where a neighbour is outside the image or has no depth), towards the camera; zero without one.
inline Float3 fresh_normal(const Float3& p, const Float3& right, const Float3& left, const Float3& below,
                           const Float3& above, float max_jump_rel, bool centred) {
  const float limit = max_jump_rel * p.z;
  const Float3 n =
      cross3(axis_difference(p, right, left, limit, centred), axis_difference(p, below, above, limit, centred));
  const float len = length(n);
  if (!(len > 0.f)) return {};
  return ((dot(n, p) > 0.f ? -1.f : 1.f) / len) * n;
}

/// Pass 2's temporal blend (eq. 4.7–4.8) of the fresh normal `n` (valid) at position p.
inline Float3 blend_with_history(const Float3& n, const Float3& p, const Pass2& in) {
  const Constants& k = in.k;
  const float* m = k.prev_from_current;
  const Float3 q{m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3], m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7],
                 m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]};
  if (!(q.z > 0.f)) return n;
  const float colf = round_half_up(k.fx * q.x / q.z + k.cx);
  const float rowf = round_half_up(k.fy * q.y / q.z + k.cy);
  if (!(colf >= 0.f && colf <= static_cast<float>(k.width - 1) && rowf >= 0.f &&
        rowf <= static_cast<float>(k.height - 1))) {
    return n;
  }
  const int col = static_cast<int>(colf), row = static_cast<int>(rowf);
  const float previous_z =
      in.prev_positions[static_cast<std::size_t>(row) * static_cast<std::size_t>(k.width) + static_cast<std::size_t>(col)].z;
  if (!(previous_z > 0.f) || std::fabs(previous_z - q.z) > k.disocclusion_m) return n;

  const History& history = *in.history;
  const auto i0 = static_cast<std::size_t>((row >> 1) * history.width + (col >> 1));
  const Float3 h{history.x[i0], history.y[i0], history.z[i0]};
  if (std::isnan(h.x)) return n;  // no valid history normal

  const float c_n = std::fabs(dot(h, n));         // eq. 4.7
  const float c = k.blend_base * c_n + (1.f - c_n);  // eq. 4.8
  const Float3 blended = normalized_or_zero(c * h + (1.f - c) * n);
  return is_valid_normal(blended) ? blended : n;
}

/// Records pixel (r, c), already written to `normals`, as a hole. Columns must come in order.
inline void record_hole(const Pass2& in, int r, int c) {
  const auto row_start = static_cast<std::size_t>(r) * static_cast<std::size_t>(in.k.width);
  const auto j = row_start + static_cast<std::size_t>(in.hole_counts[r]++);
  in.hole_columns[j] = static_cast<std::uint32_t>(c);
  in.hole_values[j] = in.normals[row_start + static_cast<std::size_t>(c)];
  in.hole_bits[static_cast<std::size_t>(r) * static_cast<std::size_t>(in.hole_words) + static_cast<std::size_t>(c / 32)] |=
      1u << (c % 32);
}

/// Starts row r's hole records.
inline void clear_holes(const Pass2& in, int r) {
  in.hole_counts[r] = 0;
  std::uint32_t* bits = in.hole_bits + static_cast<std::size_t>(r) * static_cast<std::size_t>(in.hole_words);
  std::fill(bits, bits + in.hole_words, 0u);
}

/// Pixel (r, c) of the blended map before any hole was filled.
inline Float3 unfilled(const Pass2& in, int r, int c) {
  const auto row_start = static_cast<std::size_t>(r) * static_cast<std::size_t>(in.k.width);
  const std::uint32_t bits =
      in.hole_bits[static_cast<std::size_t>(r) * static_cast<std::size_t>(in.hole_words) + static_cast<std::size_t>(c / 32)];
  if ((bits >> (c % 32) & 1u) == 0) return in.normals[row_start + static_cast<std::size_t>(c)];
  const std::uint32_t* columns = in.hole_columns + row_start;
  const auto j = std::lower_bound(columns, columns + in.hole_counts[r], static_cast<std::uint32_t>(c)) - columns;
  return in.hole_values[row_start + static_cast<std::size_t>(j)];
}

/// Fills row r's holes with the normalised sum of their 4-neighbours' unfilled normals, where
/// that is a valid normal. Needs rows r − 1 and r + 1 blended (with their holes recorded).
inline void fill_row(const Pass2& in, int r) {
  const int width = in.k.width, height = in.k.height;
  const auto row_start = static_cast<std::size_t>(r) * static_cast<std::size_t>(width);
  for (int j = 0; j < in.hole_counts[r]; ++j) {
    const int c = static_cast<int>(in.hole_columns[row_start + static_cast<std::size_t>(j)]);
    Float3 sum;
    if (r > 0) sum += unfilled(in, r - 1, c);
    if (r + 1 < height) sum += unfilled(in, r + 1, c);
    if (c > 0) sum += unfilled(in, r, c - 1);
    if (c + 1 < width) sum += unfilled(in, r, c + 1);
    const Float3 n = normalized_or_zero(sum);
    if (is_valid_normal(n)) in.normals[row_start + static_cast<std::size_t>(c)] = n;
  }
}

/// Pass 2 for pixel (r, c) with the scalar arithmetic.
inline void pass2_pixel(const Pass2& in, int r, int c) {
  const Constants& k = in.k;
  const std::size_t i = static_cast<std::size_t>(r) * static_cast<std::size_t>(k.width) + static_cast<std::size_t>(c);
  Float3 p, n;
  if (in.depth) {
    const auto position = [&](int row, int col) -> Float3 {
      if (row < 0 || col < 0 || row >= k.height || col >= k.width) return {};
      const float z = in.depth[static_cast<std::size_t>(row) * static_cast<std::size_t>(k.width) + static_cast<std::size_t>(col)];
      const float zv = valid_depth_value(z) ? z : 0.f;
      const float y_scale = (static_cast<float>(row) - k.cy) * k.inv_fy;
      return {in.x_scale[col] * zv, y_scale * zv, zv};
    };
    const int s = k.stride;
    p = position(r, c);
    in.positions_out[i] = p;
    n = fresh_normal(p, position(r, c + s), position(r, c - s), position(r + s, c), position(r - s, c), k.max_jump_rel,
                     k.centred);
  } else {
    p = in.positions_in[i];
    n = in.normals[i];
  }
  const bool has_normal = is_valid_normal(n);
  if (in.prev_positions && has_normal) n = blend_with_history(n, p, in);
  in.normals[i] = n;
  if (p.z > 0.f && !has_normal) record_hole(in, r, c);
}

// ---- AVX2 (normals_raw_depth_avx2.cpp; x86-64 only) -------------------------------------------

/// True when the CPU and the OS support AVX2 and this build has the AVX2 loops.
[[nodiscard]] bool avx2_available();
/// Level-0 texel row hr (all columns) into row out_row, same results as level0_texel.
void level0_row_avx2(const Float3* previous, int width, int height, int hr, Pyramid& out, int out_row);
/// Row r of coarse `level` (all columns), same results as coarse_texel.
void coarse_row_avx2(Pyramid& p, int level, int r);
/// Level-0 texel row r of the resolved history (all columns) into row out_row, same results as
/// resolve_texel.
void resolve_row_avx2(const Pyramid& p, const Constants& k, int r, History& out, int out_row);
/// Pass 2 for row r (all columns), same results as pass2_pixel. Requires width·height·3 < 2^31
/// (gather indices).
void pass2_row_avx2(const Pass2& in, int r);

}  // namespace relight::reconstruct::method1
