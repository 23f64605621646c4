// AVX2 loops of method 1 on the CPU (see normals_raw_depth_kernels.h): eight pixels or texels per
// iteration in structure-of-arrays registers, branch-free, with the same operations in the same
// order as the scalar functions of the kernels header, so the maps are bit-identical. Each
// function carries target("avx2") instead of the file being compiled with -mavx2, so that no
// inline function of a shared header is emitted here with AVX2 instructions and then chosen by
// the linker for the baseline code; callers check avx2_available() first. Lambdas would not
// inherit the target attribute, hence the small named helpers.
#include "normals_raw_depth_kernels.h"

#if defined(__x86_64__) || defined(__i386__)

#include <immintrin.h>

#include <cfloat>
#include <limits>

#define RELIGHT_AVX2 __attribute__((target("avx2")))

namespace relight::reconstruct::method1 {

namespace {

struct V3 {
  __m256 x, y, z;
};

RELIGHT_AVX2 inline __m256 splat(float v) { return _mm256_set1_ps(v); }
RELIGHT_AVX2 inline __m256 abs8(__m256 v) { return _mm256_andnot_ps(_mm256_set1_ps(-0.f), v); }
RELIGHT_AVX2 inline __m256 gt(__m256 a, __m256 b) { return _mm256_cmp_ps(a, b, _CMP_GT_OQ); }
RELIGHT_AVX2 inline __m256 ge(__m256 a, __m256 b) { return _mm256_cmp_ps(a, b, _CMP_GE_OQ); }
RELIGHT_AVX2 inline __m256 le(__m256 a, __m256 b) { return _mm256_cmp_ps(a, b, _CMP_LE_OQ); }
RELIGHT_AVX2 inline __m256 both(__m256 a, __m256 b) { return _mm256_and_ps(a, b); }
/// mask ? a : b per lane.
RELIGHT_AVX2 inline __m256 select(__m256 mask, __m256 a, __m256 b) { return _mm256_blendv_ps(b, a, mask); }
RELIGHT_AVX2 inline V3 select(__m256 mask, const V3& a, const V3& b) {
  return {select(mask, a.x, b.x), select(mask, a.y, b.y), select(mask, a.z, b.z)};
}
/// mask ? v : 0 per lane.
RELIGHT_AVX2 inline V3 keep(__m256 mask, const V3& v) {
  return {_mm256_and_ps(mask, v.x), _mm256_and_ps(mask, v.y), _mm256_and_ps(mask, v.z)};
}
RELIGHT_AVX2 inline V3 zero3() { return {_mm256_setzero_ps(), _mm256_setzero_ps(), _mm256_setzero_ps()}; }
RELIGHT_AVX2 inline V3 plus(const V3& a, const V3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
RELIGHT_AVX2 inline __m256 dot3(const V3& a, const V3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

/// is_valid_normal: every component finite and a positive squared length.
RELIGHT_AVX2 inline __m256 valid_normal(const V3& n) {
  const __m256 max = splat(FLT_MAX);
  const __m256 finite = both(both(le(abs8(n.x), max), le(abs8(n.y), max)), le(abs8(n.z), max));
  return both(finite, gt(dot3(n, n), _mm256_setzero_ps()));
}

/// valid_normal for a vector scaled by ±1/|v| (normalized_or_zero, fresh_normal8): its length is
/// about 1 unless the scale overflowed, so its components are finite exactly when its squared
/// length is, and the test needs no per-component check.
RELIGHT_AVX2 inline __m256 valid_scaled_normal(const V3& n) {
  const __m256 d = dot3(n, n);
  return both(gt(d, _mm256_setzero_ps()), le(d, splat(FLT_MAX)));
}

/// normalized_or_zero: (1 / |v|) · v, zero where |v| is not positive.
RELIGHT_AVX2 inline V3 normalized_or_zero(const V3& v) {
  const __m256 len = _mm256_sqrt_ps(dot3(v, v));
  const __m256 inv = splat(1.f) / len;
  return keep(gt(len, _mm256_setzero_ps()), {inv * v.x, inv * v.y, inv * v.z});
}

/// round_half_up.
RELIGHT_AVX2 inline __m256 round_half_up(__m256 x) {
  return _mm256_round_ps(x + splat(0.5f), _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
}

/// Eight consecutive Float3 into three registers.
RELIGHT_AVX2 inline V3 load_aos8(const Float3* p) {
  const float* f = reinterpret_cast<const float*>(p);
  const __m256 m03 = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(f)), _mm_loadu_ps(f + 12), 1);
  const __m256 m14 = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(f + 4)), _mm_loadu_ps(f + 16), 1);
  const __m256 m25 = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(f + 8)), _mm_loadu_ps(f + 20), 1);
  const __m256 xy = _mm256_shuffle_ps(m14, m25, _MM_SHUFFLE(2, 1, 3, 2));
  const __m256 yz = _mm256_shuffle_ps(m03, m14, _MM_SHUFFLE(1, 0, 2, 1));
  return {_mm256_shuffle_ps(m03, xy, _MM_SHUFFLE(2, 0, 3, 0)), _mm256_shuffle_ps(yz, xy, _MM_SHUFFLE(3, 1, 2, 0)),
          _mm256_shuffle_ps(yz, m25, _MM_SHUFFLE(3, 0, 3, 1))};
}

/// Three registers into eight consecutive Float3.
RELIGHT_AVX2 inline void store_aos8(Float3* p, const V3& v) {
  float* f = reinterpret_cast<float*>(p);
  const __m256 rxy = _mm256_shuffle_ps(v.x, v.y, _MM_SHUFFLE(2, 0, 2, 0));
  const __m256 ryz = _mm256_shuffle_ps(v.y, v.z, _MM_SHUFFLE(3, 1, 3, 1));
  const __m256 rzx = _mm256_shuffle_ps(v.z, v.x, _MM_SHUFFLE(3, 1, 2, 0));
  const __m256 r03 = _mm256_shuffle_ps(rxy, rzx, _MM_SHUFFLE(2, 0, 2, 0));
  const __m256 r14 = _mm256_shuffle_ps(ryz, rxy, _MM_SHUFFLE(3, 1, 2, 0));
  const __m256 r25 = _mm256_shuffle_ps(rzx, ryz, _MM_SHUFFLE(3, 1, 3, 1));
  _mm256_storeu_ps(f, _mm256_permute2f128_ps(r03, r14, 0x20));
  _mm256_storeu_ps(f + 8, _mm256_permute2f128_ps(r25, r03, 0x30));
  _mm256_storeu_ps(f + 16, _mm256_permute2f128_ps(r14, r25, 0x31));
}

RELIGHT_AVX2 inline __m256 load_halves(const float* low, const float* high) {
  return _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(low)), _mm_loadu_ps(high), 1);
}

/// Float3 p[0], p[2], …, p[14] into three registers. Reads one float past p[14].
RELIGHT_AVX2 inline V3 load_stride2(const Float3* p) {
  const float* f = reinterpret_cast<const float*>(p);
  const __m256 a = load_halves(f, f + 24), b = load_halves(f + 6, f + 30);
  const __m256 c = load_halves(f + 12, f + 36), d = load_halves(f + 18, f + 42);
  const __m256 t0 = _mm256_unpacklo_ps(a, b), t1 = _mm256_unpackhi_ps(a, b);
  const __m256 t2 = _mm256_unpacklo_ps(c, d), t3 = _mm256_unpackhi_ps(c, d);
  return {_mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(1, 0, 1, 0)), _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(3, 2, 3, 2)),
          _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(1, 0, 1, 0))};
}

/// 64-bit quarters 0, 2, 1, 3: after a lane-wise shuffle of a and b, a's elements then b's.
RELIGHT_AVX2 inline __m256 quarters_in_order(__m256 v) {
  return _mm256_castpd_ps(_mm256_permute4x64_pd(_mm256_castps_pd(v), _MM_SHUFFLE(3, 1, 2, 0)));
}

/// f[0], f[2], …, f[14] and f[1], f[3], …, f[15].
RELIGHT_AVX2 inline void load_even_odd(const float* f, __m256& even, __m256& odd) {
  const __m256 a = _mm256_loadu_ps(f), b = _mm256_loadu_ps(f + 8);
  even = quarters_in_order(_mm256_shuffle_ps(a, b, _MM_SHUFFLE(2, 0, 2, 0)));
  odd = quarters_in_order(_mm256_shuffle_ps(a, b, _MM_SHUFFLE(3, 1, 3, 1)));
}

/// pow128(clamp01(v)): std::clamp's NaN behaviour kept (min_ps/max_ps return their second
/// operand on NaN).
RELIGHT_AVX2 inline __m256 curvature_coefficient(__m256 v) {
  __m256 x = _mm256_max_ps(_mm256_setzero_ps(), _mm256_min_ps(splat(1.f), v));
  for (int i = 0; i < 7; ++i) x = x * x;
  return x;
}

// ---- Pass 2 helpers ---------------------------------------------------------------------------

/// Eight depths of `row` from column `col` on, zero outside [0, width).
RELIGHT_AVX2 inline __m256 depth8(const float* row, int col, int width) {
  if (col >= 0 && col + 8 <= width) return _mm256_loadu_ps(row + col);
  alignas(32) float tmp[8];
  for (int i = 0; i < 8; ++i) tmp[i] = col + i >= 0 && col + i < width ? row[col + i] : 0.f;
  return _mm256_load_ps(tmp);
}

/// positions_from_depth's validity: the depth where valid, else 0.
RELIGHT_AVX2 inline __m256 valid_depth(__m256 z) { return _mm256_and_ps(both(gt(z, _mm256_setzero_ps()), le(z, splat(3.4e38f))), z); }

RELIGHT_AVX2 inline V3 position8(__m256 x_scale, __m256 y_scale, __m256 z) { return {x_scale * z, y_scale * z, z}; }

/// axis_difference for eight pixels.
RELIGHT_AVX2 inline V3 axis_difference8(const V3& p, const V3& forward, const V3& backward, __m256 limit,
                                        __m256 centred) {
  const __m256 zero = _mm256_setzero_ps();
  const __m256 use_forward = both(gt(forward.z, zero), le(abs8(forward.z - p.z), limit));
  const __m256 use_backward = both(gt(backward.z, zero), le(abs8(backward.z - p.z), limit));
  const V3 one_sided = select(use_forward, V3{forward.x - p.x, forward.y - p.y, forward.z - p.z},
                              keep(use_backward, V3{p.x - backward.x, p.y - backward.y, p.z - backward.z}));
  return select(both(centred, both(use_forward, use_backward)),
                V3{forward.x - backward.x, forward.y - backward.y, forward.z - backward.z}, one_sided);
}

/// fresh_normal for eight pixels.
RELIGHT_AVX2 inline V3 fresh_normal8(const V3& p, const V3& right, const V3& left, const V3& below, const V3& above,
                                     float max_jump_rel, bool centred) {
  const __m256 limit = splat(max_jump_rel) * p.z;
  const __m256 centred_mask = _mm256_castsi256_ps(_mm256_set1_epi32(centred ? -1 : 0));
  const V3 a = axis_difference8(p, right, left, limit, centred_mask);
  const V3 b = axis_difference8(p, below, above, limit, centred_mask);
  const V3 n{a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
  const __m256 len = _mm256_sqrt_ps(dot3(n, n));
  const __m256 sign = select(gt(dot3(n, p), _mm256_setzero_ps()), splat(-1.f), splat(1.f));
  const __m256 scale = sign / len;
  return keep(gt(len, _mm256_setzero_ps()), {scale * n.x, scale * n.y, scale * n.z});
}

/// One vector of pixels between the stages of the blend (blend_with_history for eight pixels).
/// The stages run over a block of vectors each, so that the memory accesses of one vector do not
/// wait for those of the previous one.
struct BlendLanes {
  V3 p, n;            ///< position and fresh normal
  __m256 has_normal;  ///< valid fresh normal
  __m256 qz;          ///< depth of the pixel in the previous frame
  __m256 use;         ///< lanes still blending
  __m256i row, col;   ///< pixel in the previous frame (valid where use)
  V3 history;         ///< resolved history normal (NaN: none)
  // Coherent lanes: every blending lane j looks up pixel (row_ref, col_ref + j) of the previous
  // frame, so each lookup is a plain load of eight neighbours plus a permutation (which the
  // hardware prefetchers follow) instead of a gather. Same values either way.
  bool coherent = false;
  int row_ref = 0, col_ref = 0;
};

RELIGHT_AVX2 inline __m256i iota8() { return _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7); }

/// Lane j of v, for j in [0, 8).
RELIGHT_AVX2 inline int lane(__m256i v, int j) {
  return _mm256_cvtsi256_si32(_mm256_permutevar8x32_epi32(v, _mm256_set1_epi32(j)));
}

/// Eight elements of `array` for lanes j = 0…7 at columns col_ref + j of a finer grid:
/// element base + ((col_ref + j) >> shift) − (col_ref >> shift). Reads array[base … base + 7]
/// (the pyramid arrays are padded).
RELIGHT_AVX2 inline __m256 load_coherent(const float* array, std::ptrdiff_t base, int col_ref, int shift) {
  const __m256i cols = _mm256_add_epi32(_mm256_set1_epi32(col_ref), iota8());
  const __m256i offsets = _mm256_sub_epi32(_mm256_srli_epi32(cols, shift), _mm256_set1_epi32(col_ref >> shift));
  return _mm256_permutevar8x32_ps(_mm256_loadu_ps(array + base), offsets);
}

/// Stage 1: reprojection into the previous frame.
RELIGHT_AVX2 inline void reproject8(const Constants& k, BlendLanes& b) {
  const float* m = k.prev_from_current;
  const __m256 zero = _mm256_setzero_ps();
  const V3& p = b.p;
  const V3 q{splat(m[0]) * p.x + splat(m[1]) * p.y + splat(m[2]) * p.z + splat(m[3]),
             splat(m[4]) * p.x + splat(m[5]) * p.y + splat(m[6]) * p.z + splat(m[7]),
             splat(m[8]) * p.x + splat(m[9]) * p.y + splat(m[10]) * p.z + splat(m[11])};
  const __m256 colf = round_half_up(splat(k.fx) * q.x / q.z + splat(k.cx));
  const __m256 rowf = round_half_up(splat(k.fy) * q.y / q.z + splat(k.cy));
  const __m256 inside = both(both(ge(colf, zero), le(colf, splat(static_cast<float>(k.width - 1)))),
                             both(ge(rowf, zero), le(rowf, splat(static_cast<float>(k.height - 1)))));
  b.qz = q.z;
  b.use = both(both(b.has_normal, gt(q.z, zero)), inside);
  b.col = _mm256_cvttps_epi32(colf);
  b.row = _mm256_cvttps_epi32(rowf);
  b.coherent = false;
  const int use = _mm256_movemask_ps(b.use);
  if (use == 0) return;
  const int first = __builtin_ctz(static_cast<unsigned>(use));
  b.row_ref = lane(b.row, first);
  b.col_ref = lane(b.col, first) - first;
  const __m256i expected_col = _mm256_add_epi32(_mm256_set1_epi32(b.col_ref), iota8());
  const __m256i match = _mm256_and_si256(_mm256_cmpeq_epi32(b.row, _mm256_set1_epi32(b.row_ref)),
                                         _mm256_cmpeq_epi32(b.col, expected_col));
  b.coherent = b.col_ref >= 0 && b.col_ref + 7 < k.width &&
               (_mm256_movemask_ps(_mm256_andnot_ps(_mm256_castsi256_ps(match), b.use)) == 0);
}

/// Stage 2: the disocclusion test on the previous depth and the resolved history normal.
RELIGHT_AVX2 inline void look_up_history8(const Pass2& in, BlendLanes& b) {
  if (_mm256_movemask_ps(b.use) == 0) return;
  const __m256 zero = _mm256_setzero_ps();
  const History& history = *in.history;
  const int level0_width = history.width;
  __m256 previous_z;
  if (b.coherent) {
    previous_z = load_aos8(in.prev_positions + static_cast<std::ptrdiff_t>(b.row_ref) * in.k.width + b.col_ref).z;
    const std::ptrdiff_t base = static_cast<std::ptrdiff_t>(b.row_ref >> 1) * level0_width + (b.col_ref >> 1);
    b.history = {load_coherent(history.x.data(), base, b.col_ref, 1), load_coherent(history.y.data(), base, b.col_ref, 1),
                 load_coherent(history.z.data(), base, b.col_ref, 1)};
  } else {
    const __m256i pixel = _mm256_add_epi32(_mm256_mullo_epi32(b.row, _mm256_set1_epi32(in.k.width)), b.col);
    const __m256i z_index =
        _mm256_add_epi32(_mm256_add_epi32(pixel, _mm256_add_epi32(pixel, pixel)), _mm256_set1_epi32(2));
    previous_z = _mm256_mask_i32gather_ps(zero, reinterpret_cast<const float*>(in.prev_positions), z_index, b.use, 4);
    const __m256i texel = _mm256_add_epi32(
        _mm256_mullo_epi32(_mm256_srli_epi32(b.row, 1), _mm256_set1_epi32(level0_width)), _mm256_srli_epi32(b.col, 1));
    b.history = {_mm256_mask_i32gather_ps(zero, history.x.data(), texel, b.use, 4),
                 _mm256_mask_i32gather_ps(zero, history.y.data(), texel, b.use, 4),
                 _mm256_mask_i32gather_ps(zero, history.z.data(), texel, b.use, 4)};
  }
  const __m256 close = _mm256_cmp_ps(abs8(previous_z - b.qz), splat(in.k.disocclusion_m), _CMP_NGT_UQ);
  const __m256 has_history = _mm256_cmp_ps(b.history.x, b.history.x, _CMP_ORD_Q);
  b.use = both(both(b.use, has_history), both(gt(previous_z, zero), close));
}

/// Stage 3: the blend (eq. 4.7–4.8). Lanes that do not blend keep the fresh normal.
RELIGHT_AVX2 inline V3 blend_history8(const Pass2& in, const BlendLanes& b) {
  if (_mm256_movemask_ps(b.use) == 0) return b.n;
  const V3& n = b.n;
  const V3& h = b.history;
  const __m256 c_n = abs8(dot3(h, n));                              // eq. 4.7
  const __m256 c = splat(in.k.blend_base) * c_n + (splat(1.f) - c_n);  // eq. 4.8
  const __m256 c_fresh = splat(1.f) - c;
  const V3 blended = normalized_or_zero({c * h.x + c_fresh * n.x, c * h.y + c_fresh * n.y, c * h.z + c_fresh * n.z});
  return select(both(b.use, valid_scaled_normal(blended)), blended, n);
}

}  // namespace

bool avx2_available() {
  static const bool available = __builtin_cpu_supports("avx2");
  return available;
}

/// Level-0 texels hc … hc+7 of one row (level0_texel). `rows[1]` points at the top-left pixel
/// of texel hc's 2x2 block, rows[0], rows[2] and rows[3] at the same column one row above, one
/// and two rows below (null: outside the image). Reads pixels −1 … +17 of rows[1] and rows[2]
/// (one float of +17) and 0 … +16 of rows[0] and rows[3] (one float of +16).
RELIGHT_AVX2 inline void level0_texels8(const Float3* const rows[4], float* x, float* y, float* z, float* curvature) {
  const auto at = [&](int row, int offset) RELIGHT_AVX2 { return rows[row] ? load_stride2(rows[row] + offset) : zero3(); };
  const V3 centre = at(1, 0), left = at(1, -1), right = at(1, 1), above = at(0, 0), below = at(2, 0);
  const V3 below_right = at(2, 1);
  // cross_sum of level0_texel at the block's four pixels, in its order of additions.
  const V3 top_left = plus(plus(plus(plus(centre, above), below), left), right);
  const V3 top_right = plus(plus(plus(plus(right, at(0, 1)), below_right), centre), at(1, 2));
  const V3 bottom_left = plus(plus(plus(plus(below, centre), at(3, 0)), at(2, -1)), below_right);
  const V3 bottom_right = plus(plus(plus(plus(below_right, right), at(3, 1)), below), at(2, 2));
  const V3 n = normalized_or_zero(plus(plus(plus(top_left, top_right), bottom_left), bottom_right));
  const __m256 pairs = both(both(valid_normal(left), valid_normal(right)), both(valid_normal(above), valid_normal(below)));
  // std::min(a, b) is b < a ? b : a, which is _mm256_min_ps(b, a).
  const __m256 curv = _mm256_and_ps(pairs, _mm256_min_ps(dot3(above, below), dot3(left, right)));
  _mm256_storeu_ps(x, n.x);
  _mm256_storeu_ps(y, n.y);
  _mm256_storeu_ps(z, n.z);
  _mm256_storeu_ps(curvature, curvature_coefficient(curv));
}

RELIGHT_AVX2 void level0_row_avx2(const Float3* previous, int width, int height, int hr, Pyramid& out, int out_row) {
  const int r = 2 * hr;
  const Float3* row = previous + static_cast<std::ptrdiff_t>(r) * width;
  const Float3* const image_rows[4] = {r >= 1 ? row - width : nullptr, row, r + 1 < height ? row + width : nullptr,
                                       r + 2 < height ? row + 2 * width : nullptr};
  const int texels = out.levels[0].width;
  const std::ptrdiff_t o = static_cast<std::ptrdiff_t>(out_row) * texels;
  float* x = out.x.data() + o;
  float* y = out.y.data() + o;
  float* z = out.z.data() + o;
  float* curvature = out.curvature.data() + o;
  if (texels < 8) {
    for (int hc = 0; hc < texels; ++hc) level0_texel(previous, width, height, hr, hc, out, out_row);
    return;
  }
  // At the image's left and right edges: the same loop on a copy of the pixels read, with zeros
  // where they fall outside the image (as level0_texel reads them).
  const auto edge = [&](int hc) RELIGHT_AVX2 {
    Float3 pixels[4][20] = {};
    const Float3* rows[4] = {};
    for (int i = 0; i < 4; ++i) {
      if (!image_rows[i]) continue;
      for (int j = 0; j < 20; ++j) {
        const int c = 2 * hc - 1 + j;
        if (c >= 0 && c < width) pixels[i][j] = image_rows[i][c];
      }
      rows[i] = &pixels[i][1];
    }
    level0_texels8(rows, x + hc, y + hc, z + hc, curvature + hc);
  };
  edge(0);
  int hc = 8;
  for (; 2 * hc + 17 < width; hc += 8) {
    const Float3* rows[4];
    for (int i = 0; i < 4; ++i) rows[i] = image_rows[i] ? image_rows[i] + 2 * hc : nullptr;
    level0_texels8(rows, x + hc, y + hc, z + hc, curvature + hc);
  }
  if (hc < texels) edge(texels - 8);  // overlaps the last texels computed: same values
}

RELIGHT_AVX2 void coarse_row_avx2(Pyramid& p, int level, int r) {
  const LevelShape fine = p.levels[static_cast<std::size_t>(level) - 1];
  const LevelShape coarse = p.levels[static_cast<std::size_t>(level)];
  int c = 0;
  if (2 * r + 1 < fine.height) {
    const __m256 zero = _mm256_setzero_ps(), one = splat(1.f);
    const std::ptrdiff_t fine_row = fine.offset + static_cast<std::ptrdiff_t>(2 * r) * fine.width;
    const std::ptrdiff_t out_row = coarse.offset + static_cast<std::ptrdiff_t>(r) * coarse.width;
    for (; 2 * c + 16 <= fine.width; c += 8) {
      V3 children[4];
      __m256 child_curvature[4];
      for (int dr = 0; dr < 2; ++dr) {
        const std::ptrdiff_t i = fine_row + static_cast<std::ptrdiff_t>(dr) * fine.width + 2 * c;
        V3& even = children[2 * dr];
        V3& odd = children[2 * dr + 1];
        load_even_odd(p.x.data() + i, even.x, odd.x);
        load_even_odd(p.y.data() + i, even.y, odd.y);
        load_even_odd(p.z.data() + i, even.z, odd.z);
        load_even_odd(p.curvature.data() + i, child_curvature[2 * dr], child_curvature[2 * dr + 1]);
      }
      V3 sum = zero3();
      __m256 curvature = zero, count = zero;
      for (int j = 0; j < 4; ++j) {  // (0,0), (0,1), (1,0), (1,1) as coarse_texel
        const __m256 valid = valid_scaled_normal(children[j]);  // normalized_or_zero results
        sum = plus(sum, keep(valid, children[j]));
        curvature = curvature + _mm256_and_ps(valid, child_curvature[j]);
        count = count + _mm256_and_ps(valid, one);
      }
      const V3 n = normalized_or_zero(sum);
      _mm256_storeu_ps(p.x.data() + out_row + c, n.x);
      _mm256_storeu_ps(p.y.data() + out_row + c, n.y);
      _mm256_storeu_ps(p.z.data() + out_row + c, n.z);
      _mm256_storeu_ps(p.curvature.data() + out_row + c, _mm256_and_ps(gt(count, zero), curvature / count));
    }
  }
  for (; c < coarse.width; ++c) coarse_texel(p, level, r, c);
}

RELIGHT_AVX2 void resolve_row_avx2(const Pyramid& p, const Constants& k, int r, History& out, int out_row) {
  const int width = p.levels[0].width;
  const std::ptrdiff_t out_start = static_cast<std::ptrdiff_t>(out_row) * out.width;
  const int max_level = static_cast<int>(p.levels.size()) - 1;
  const __m256 zero = _mm256_setzero_ps(), max_level_f = splat(static_cast<float>(max_level));
  const float* m = k.current_from_prev;
  const std::ptrdiff_t row = static_cast<std::ptrdiff_t>(r) * width;
  int c = 0;
  for (; c + 8 <= width; c += 8) {
    const std::ptrdiff_t i0 = row + c;
    const __m256 lf = round_half_up(_mm256_loadu_ps(p.curvature.data() + i0) * max_level_f);
    const __m256i level = _mm256_cvttps_epi32(_mm256_and_ps(ge(lf, zero), _mm256_min_ps(lf, max_level_f)));
    const V3 level0{_mm256_loadu_ps(p.x.data() + i0), _mm256_loadu_ps(p.y.data() + i0), _mm256_loadu_ps(p.z.data() + i0)};
    V3 h = level0;
    for (int l = 1; l <= max_level; ++l) {
      const __m256 at_level = _mm256_castsi256_ps(_mm256_cmpeq_epi32(level, _mm256_set1_epi32(l)));
      if (_mm256_movemask_ps(at_level) == 0) continue;
      const LevelShape& shape = p.levels[static_cast<std::size_t>(l)];
      const std::ptrdiff_t base = shape.offset + static_cast<std::ptrdiff_t>(r >> l) * shape.width + (c >> l);
      const V3 texels{load_coherent(p.x.data(), base, c, l), load_coherent(p.y.data(), base, c, l),
                      load_coherent(p.z.data(), base, c, l)};
      h = select(at_level, texels, h);
    }
    h = select(valid_scaled_normal(h), h, level0);  // pyramid texels are normalized_or_zero results
    const __m256 nan = splat(std::numeric_limits<float>::quiet_NaN());
    const __m256 valid = valid_scaled_normal(h);
    _mm256_storeu_ps(out.x.data() + out_start + c, select(valid, splat(m[0]) * h.x + splat(m[1]) * h.y + splat(m[2]) * h.z, nan));
    _mm256_storeu_ps(out.y.data() + out_start + c, select(valid, splat(m[3]) * h.x + splat(m[4]) * h.y + splat(m[5]) * h.z, nan));
    _mm256_storeu_ps(out.z.data() + out_start + c, select(valid, splat(m[6]) * h.x + splat(m[7]) * h.y + splat(m[8]) * h.z, nan));
  }
  for (; c < width; ++c) resolve_texel(p, k, r, c, out, out_row);
}

RELIGHT_AVX2 void pass2_row_avx2(const Pass2& in, int r) {
  const Constants& k = in.k;
  const int width = k.width, s = k.stride;
  const std::ptrdiff_t row_start = static_cast<std::ptrdiff_t>(r) * width;
  const int vector_end = width - width % 8;
  const bool blend = in.prev_positions != nullptr;
  const float* depth_row = in.depth ? in.depth + row_start : nullptr;
  const float* below_row = in.depth && r + s < k.height ? depth_row + static_cast<std::ptrdiff_t>(s) * width : nullptr;
  const float* above_row = in.depth && r - s >= 0 ? depth_row - static_cast<std::ptrdiff_t>(s) * width : nullptr;
  const auto y_scale = [&k](int row) { return (static_cast<float>(row) - k.cy) * k.inv_fy; };
  const __m256 ys = splat(y_scale(r));
  const __m256 ys_below = splat(below_row ? y_scale(r + s) : 0.f);
  const __m256 ys_above = splat(above_row ? y_scale(r - s) : 0.f);
  constexpr int kBlock = 8;  // vectors per block: 64 pixels
  BlendLanes lanes[kBlock];
  const char* prev_bytes = reinterpret_cast<const char*>(in.prev_positions);
  for (int block = 0; block < vector_end; block += 8 * kBlock) {
    const int count = std::min(kBlock, (vector_end - block) / 8);
    for (int j = 0; j < count; ++j) {
      const int c = block + 8 * j;
      BlendLanes& b = lanes[j];
      if (depth_row) {
        const __m256 xs = _mm256_loadu_ps(in.x_scale + c);
        b.p = position8(xs, ys, valid_depth(_mm256_loadu_ps(depth_row + c)));
        const V3 right =
            position8(_mm256_loadu_ps(in.x_scale + c + s), ys, valid_depth(depth8(depth_row, c + s, width)));
        const V3 left =
            position8(_mm256_loadu_ps(in.x_scale + c - s), ys, valid_depth(depth8(depth_row, c - s, width)));
        const V3 below = below_row ? position8(xs, ys_below, valid_depth(_mm256_loadu_ps(below_row + c))) : zero3();
        const V3 above = above_row ? position8(xs, ys_above, valid_depth(_mm256_loadu_ps(above_row + c))) : zero3();
        store_aos8(in.positions_out + row_start + c, b.p);
        b.n = fresh_normal8(b.p, right, left, below, above, k.max_jump_rel, k.centred);
      } else {
        b.p = load_aos8(in.positions_in + row_start + c);
        b.n = load_aos8(in.normals + row_start + c);
      }
      b.has_normal = depth_row ? valid_scaled_normal(b.n) : valid_normal(b.n);
      if (blend) {
        reproject8(k, b);
        // The previous positions are read by gathers, which the hardware prefetchers do not
        // follow; neighbouring pixels reproject to neighbouring pixels, so fetch ahead of lane 0.
        if (_mm256_movemask_ps(b.use) & 1) {
          const std::ptrdiff_t pixel = static_cast<std::ptrdiff_t>(_mm256_cvtsi256_si32(b.row)) * width +
                                       _mm256_cvtsi256_si32(b.col);
          const char* ahead = prev_bytes + (pixel + 8 * kBlock) * static_cast<std::ptrdiff_t>(sizeof(Float3));
          _mm_prefetch(ahead, _MM_HINT_T0);
          _mm_prefetch(ahead + 64, _MM_HINT_T0);
        }
      }
    }
    if (blend) {
      for (int j = 0; j < count; ++j) look_up_history8(in, lanes[j]);
    }
    for (int j = 0; j < count; ++j) {
      const int c = block + 8 * j;
      const BlendLanes& b = lanes[j];
      store_aos8(in.normals + row_start + c, blend ? blend_history8(in, b) : b.n);
      auto holes = static_cast<unsigned>(
          _mm256_movemask_ps(_mm256_andnot_ps(b.has_normal, gt(b.p.z, _mm256_setzero_ps()))));
      while (holes != 0) {
        record_hole(in, r, c + __builtin_ctz(holes));
        holes &= holes - 1;
      }
    }
  }
  for (int c = vector_end; c < width; ++c) pass2_pixel(in, r, c);
}

}  // namespace relight::reconstruct::method1

#else  // not x86: the scalar loops only

namespace relight::reconstruct::method1 {

bool avx2_available() { return false; }
void level0_row_avx2(const Float3* previous, int width, int height, int hr, Pyramid& out, int out_row) {
  for (int hc = 0; hc < out.levels[0].width; ++hc) level0_texel(previous, width, height, hr, hc, out, out_row);
}
void coarse_row_avx2(Pyramid& p, int level, int r) {
  for (int c = 0; c < p.levels[static_cast<std::size_t>(level)].width; ++c) coarse_texel(p, level, r, c);
}
void resolve_row_avx2(const Pyramid& p, const Constants& k, int r, History& out, int out_row) {
  for (int c = 0; c < p.levels[0].width; ++c) resolve_texel(p, k, r, c, out, out_row);
}
void pass2_row_avx2(const Pass2& in, int r) {
  for (int c = 0; c < in.k.width; ++c) pass2_pixel(in, r, c);
}

}  // namespace relight::reconstruct::method1

#endif
