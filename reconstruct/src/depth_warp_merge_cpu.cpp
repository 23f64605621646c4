// CPU reference rasteriser and merge of method 2 (definition in depth_warp_merge.h). The source
// rows are split into bands; each band rasterises into its own z-buffer and the bands are
// combined with the same z-test in band order (ties keep the earlier triangle), so the result
// does not depend on the thread count.
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include "relight/core/buffers.h"
#include "relight/core/parallel.h"
#include "relight/reconstruct/buffers.h"
#include "relight/reconstruct/depth_warp_merge.h"

namespace relight::reconstruct {

namespace {

constexpr float kFar = std::numeric_limits<float>::infinity();

struct WarpedVertex {
  float u = 0.f, v = 0.f, z = 0.f;  // z <= 0: no vertex
  float weight = 0.f;
};

// One band's z-buffer. Kept between calls (see WarpScratch): allocating and faulting in these
// pages every frame cost more than filling them.
struct ZBuffer {
  std::vector<float> z;
  std::vector<float> weight;
};

// What warp_depth needs besides its outputs, reused by the next call on the same thread.
struct WarpScratch {
  std::vector<WarpedVertex> vertices;
  std::vector<ZBuffer> buffers;
};

float edge(float ax, float ay, float bx, float by, float px, float py) {
  return (bx - ax) * (py - ay) - (by - ay) * (px - ax);
}

// A triangle that survived the rejection tests: its pixel-centre bounding box and what its pixels share.
struct TriangleSetup {
  int x0 = 0, x1 = -1, y0 = 0, y1 = -1;
  float inv_area = 0.f;
  float weight = 0.f;
};

// False for a triangle that covers no pixel centre or must not be drawn (missing vertex, mesh
// edge across a discontinuity, degenerate). The cheap tests come first: most cells of a warp
// that shrinks the image hold no pixel centre.
bool set_up(const WarpedVertex& a, const WarpedVertex& b, const WarpedVertex& c, int width, int height,
            const DepthWarpMergeOptions& options, TriangleSetup& t) {
  if (!(a.z > 0.f && b.z > 0.f && c.z > 0.f)) return false;
  // The bounding box is widened by a rounding margin: a vertex that φ(φ⁻¹(·)) maps to 2.0000002
  // must still cover pixel centre 2.
  constexpr float margin = 1e-3f;
  t.x0 = std::max(0, static_cast<int>(std::ceil(std::min({a.u, b.u, c.u}) - margin)));
  t.x1 = std::min(width - 1, static_cast<int>(std::floor(std::max({a.u, b.u, c.u}) + margin)));
  if (t.x0 > t.x1) return false;
  t.y0 = std::max(0, static_cast<int>(std::ceil(std::min({a.v, b.v, c.v}) - margin)));
  t.y1 = std::min(height - 1, static_cast<int>(std::floor(std::max({a.v, b.v, c.v}) + margin)));
  if (t.y0 > t.y1) return false;
  const float z_min = std::min({a.z, b.z, c.z});
  const float z_max = std::max({a.z, b.z, c.z});
  if (z_max - z_min > options.max_edge_m + options.max_edge_rel * z_min) return false;  // across a discontinuity
  const float area = edge(a.u, a.v, b.u, b.v, c.u, c.v);
  if (std::fabs(area) < 1e-8f) return false;
  t.inv_area = 1.f / area;
  t.weight = std::min({a.weight, b.weight, c.weight});
  return true;
}

constexpr float kInclusive = -1e-4f;  // pixel centres on a shared edge belong to both triangles

void z_test(ZBuffer& target, std::size_t index, float z, float weight) {
  if (z < target.z[index]) {
    target.z[index] = z;
    target.weight[index] = weight;
  }
}

#if defined(__SSE2__)
// The pixel centres of the bounding box in 2×2 tiles, four lanes at a time (SSE2 is part of
// x86-64's baseline). Every lane performs the scalar loop's operations in the same order, and
// IEEE single precision gives each the same result, so the z-buffer is the same bit for bit.
void cover(const WarpedVertex& a, const WarpedVertex& b, const WarpedVertex& c, const TriangleSetup& t, int width,
           ZBuffer& target) {
  const __m128 inclusive = _mm_set1_ps(kInclusive);
  const __m128 one = _mm_set1_ps(1.f);
  const __m128 inv_area = _mm_set1_ps(t.inv_area);
  const __m128 bc_u = _mm_set1_ps(c.u - b.u), bc_v = _mm_set1_ps(c.v - b.v);
  const __m128 ca_u = _mm_set1_ps(a.u - c.u), ca_v = _mm_set1_ps(a.v - c.v);
  const __m128 b_u = _mm_set1_ps(b.u), b_v = _mm_set1_ps(b.v);
  const __m128 c_u = _mm_set1_ps(c.u), c_v = _mm_set1_ps(c.v);
  const __m128 a_z = _mm_set1_ps(a.z), b_z = _mm_set1_ps(b.z), c_z = _mm_set1_ps(c.z);
  const __m128 lane_dx = _mm_setr_ps(0.f, 1.f, 0.f, 1.f), lane_dy = _mm_setr_ps(0.f, 0.f, 1.f, 1.f);
  alignas(16) float z[4];
  for (int y = t.y0; y <= t.y1; y += 2) {
    const __m128 py = _mm_add_ps(_mm_set1_ps(static_cast<float>(y)), lane_dy);
    const int rows_mask = y + 1 <= t.y1 ? 0xF : 0x3;
    for (int x = t.x0; x <= t.x1; x += 2) {
      const __m128 px = _mm_add_ps(_mm_set1_ps(static_cast<float>(x)), lane_dx);
      const __m128 w0 = _mm_mul_ps(
          _mm_sub_ps(_mm_mul_ps(bc_u, _mm_sub_ps(py, b_v)), _mm_mul_ps(bc_v, _mm_sub_ps(px, b_u))), inv_area);
      const __m128 w1 = _mm_mul_ps(
          _mm_sub_ps(_mm_mul_ps(ca_u, _mm_sub_ps(py, c_v)), _mm_mul_ps(ca_v, _mm_sub_ps(px, c_u))), inv_area);
      const __m128 w2 = _mm_sub_ps(_mm_sub_ps(one, w0), w1);
      const __m128 outside = _mm_or_ps(_mm_or_ps(_mm_cmplt_ps(w0, inclusive), _mm_cmplt_ps(w1, inclusive)),
                                       _mm_cmplt_ps(w2, inclusive));
      int inside = ~_mm_movemask_ps(outside) & rows_mask & (x + 1 <= t.x1 ? 0xF : 0x5);
      if (inside == 0) continue;
      _mm_store_ps(z, _mm_div_ps(one, _mm_add_ps(_mm_add_ps(_mm_div_ps(w0, a_z), _mm_div_ps(w1, b_z)),
                                                 _mm_div_ps(w2, c_z))));
      const std::size_t index = static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x);
      for (; inside != 0; inside &= inside - 1) {
        const int lane = __builtin_ctz(static_cast<unsigned>(inside));
        z_test(target, index + static_cast<std::size_t>(lane & 1) + static_cast<std::size_t>(lane >> 1) * static_cast<std::size_t>(width), z[lane], t.weight);
      }
    }
  }
}

// Triangle set-up of four neighbouring cells at once: lane i holds the triangle of cell c + i.
// _mm_min_ps(b, a) is "b < a ? b : a", which is std::min's choice, so every lane computes what
// set_up computes. Lanes whose bounding box lies far outside the image or is not finite
// (`wild`) go through the scalar set_up instead, whose float-to-int conversion they would not
// reproduce.
struct Lanes {
  __m128 u, v, z, weight;
};

Lanes load_lanes(const WarpedVertex* first) {
  const float* f = &first->u;
  static_assert(sizeof(WarpedVertex) == 4 * sizeof(float));
  __m128 u = _mm_loadu_ps(f), v = _mm_loadu_ps(f + 4), z = _mm_loadu_ps(f + 8), weight = _mm_loadu_ps(f + 12);
  _MM_TRANSPOSE4_PS(u, v, z, weight);
  return {u, v, z, weight};
}

__m128 min3(__m128 a, __m128 b, __m128 c) { return _mm_min_ps(c, _mm_min_ps(b, a)); }
__m128 max3(__m128 a, __m128 b, __m128 c) { return _mm_max_ps(c, _mm_max_ps(b, a)); }

__m128i select(__m128i mask, __m128i if_set, __m128i if_clear) {
  return _mm_or_si128(_mm_and_si128(mask, if_set), _mm_andnot_si128(mask, if_clear));
}

// (int)std::ceil(t) and (int)std::floor(t) for |t| < 2^30.
__m128i ceil_int(__m128 t) {
  const __m128i i = _mm_cvttps_epi32(t);
  return _mm_sub_epi32(i, _mm_castps_si128(_mm_cmplt_ps(_mm_cvtepi32_ps(i), t)));
}
__m128i floor_int(__m128 t) {
  const __m128i i = _mm_cvttps_epi32(t);
  return _mm_add_epi32(i, _mm_castps_si128(_mm_cmpgt_ps(_mm_cvtepi32_ps(i), t)));
}

__m128 tame(__m128 t) {  // all ones where |t| < 2^30 (false for NaN)
  return _mm_cmplt_ps(_mm_andnot_ps(_mm_set1_ps(-0.f), t), _mm_set1_ps(1073741824.f));
}

struct SetupLanes {
  alignas(16) int x0[4], x1[4], y0[4], y1[4];
  alignas(16) float inv_area[4], weight[4];
  int accepted = 0;  // bit i: lane i is drawn with these values
  int wild = 0;      // bit i: lane i needs the scalar set_up
};

void set_up_lanes(const Lanes& a, const Lanes& b, const Lanes& c, int width, int height,
                  const DepthWarpMergeOptions& options, SetupLanes& t) {
  const __m128 zero = _mm_setzero_ps();
  const __m128 valid = _mm_and_ps(_mm_and_ps(_mm_cmpgt_ps(a.z, zero), _mm_cmpgt_ps(b.z, zero)), _mm_cmpgt_ps(c.z, zero));
  const __m128 margin = _mm_set1_ps(1e-3f);
  const __m128 u_low = _mm_sub_ps(min3(a.u, b.u, c.u), margin), u_high = _mm_add_ps(max3(a.u, b.u, c.u), margin);
  const __m128 v_low = _mm_sub_ps(min3(a.v, b.v, c.v), margin), v_high = _mm_add_ps(max3(a.v, b.v, c.v), margin);
  const __m128 tame_box = _mm_and_ps(_mm_and_ps(tame(u_low), tame(u_high)), _mm_and_ps(tame(v_low), tame(v_high)));
  const __m128i zero_i = _mm_setzero_si128();
  const __m128i last_x = _mm_set1_epi32(width - 1), last_y = _mm_set1_epi32(height - 1);
  __m128i x0 = ceil_int(u_low), y0 = ceil_int(v_low), x1 = floor_int(u_high), y1 = floor_int(v_high);
  x0 = select(_mm_cmpgt_epi32(x0, zero_i), x0, zero_i);
  y0 = select(_mm_cmpgt_epi32(y0, zero_i), y0, zero_i);
  x1 = select(_mm_cmplt_epi32(x1, last_x), x1, last_x);
  y1 = select(_mm_cmplt_epi32(y1, last_y), y1, last_y);
  const __m128 empty = _mm_castsi128_ps(_mm_or_si128(_mm_cmpgt_epi32(x0, x1), _mm_cmpgt_epi32(y0, y1)));
  const __m128 z_min = min3(a.z, b.z, c.z), z_max = max3(a.z, b.z, c.z);
  const __m128 across = _mm_cmpgt_ps(
      _mm_sub_ps(z_max, z_min),
      _mm_add_ps(_mm_set1_ps(options.max_edge_m), _mm_mul_ps(_mm_set1_ps(options.max_edge_rel), z_min)));
  const __m128 area = _mm_sub_ps(_mm_mul_ps(_mm_sub_ps(b.u, a.u), _mm_sub_ps(c.v, a.v)),
                                 _mm_mul_ps(_mm_sub_ps(b.v, a.v), _mm_sub_ps(c.u, a.u)));
  const __m128 degenerate = _mm_cmplt_ps(_mm_andnot_ps(_mm_set1_ps(-0.f), area), _mm_set1_ps(1e-8f));
  const __m128 rejected = _mm_or_ps(_mm_or_ps(empty, across), degenerate);
  t.wild = _mm_movemask_ps(_mm_andnot_ps(tame_box, valid));
  t.accepted = _mm_movemask_ps(_mm_andnot_ps(rejected, _mm_and_ps(valid, tame_box)));
  if (t.accepted == 0) return;
  _mm_store_si128(reinterpret_cast<__m128i*>(t.x0), x0);
  _mm_store_si128(reinterpret_cast<__m128i*>(t.x1), x1);
  _mm_store_si128(reinterpret_cast<__m128i*>(t.y0), y0);
  _mm_store_si128(reinterpret_cast<__m128i*>(t.y1), y1);
  _mm_store_ps(t.inv_area, _mm_div_ps(_mm_set1_ps(1.f), area));
  _mm_store_ps(t.weight, min3(a.weight, b.weight, c.weight));
}

TriangleSetup lane(const SetupLanes& t, int i) {
  return {t.x0[i], t.x1[i], t.y0[i], t.y1[i], t.inv_area[i], t.weight[i]};
}
#else
void cover(const WarpedVertex& a, const WarpedVertex& b, const WarpedVertex& c, const TriangleSetup& t, int width,
           ZBuffer& target) {
  for (int y = t.y0; y <= t.y1; ++y) {
    const float py = static_cast<float>(y);
    for (int x = t.x0; x <= t.x1; ++x) {
      const float px = static_cast<float>(x);
      const float w0 = edge(b.u, b.v, c.u, c.v, px, py) * t.inv_area;
      const float w1 = edge(c.u, c.v, a.u, a.v, px, py) * t.inv_area;
      const float w2 = 1.f - w0 - w1;
      if (w0 < kInclusive || w1 < kInclusive || w2 < kInclusive) continue;
      const float z = 1.f / (w0 / a.z + w1 / b.z + w2 / c.z);  // 1/z is affine in screen space
      z_test(target, static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x), z, t.weight);
    }
  }
}
#endif

void rasterise(const WarpedVertex& a, const WarpedVertex& b, const WarpedVertex& c, int width, int height,
               const DepthWarpMergeOptions& options, ZBuffer& target) {
  TriangleSetup t;
  if (set_up(a, b, c, width, height, options, t)) cover(a, b, c, t, width, target);
}

#if defined(__SSE2__)
bool single_tile(const TriangleSetup& t) { return t.x1 - t.x0 <= 1 && t.y1 - t.y0 <= 1; }

__attribute__((target("avx"))) __m256 halves(float low, float high) {
  return _mm256_setr_ps(low, low, low, low, high, high, high, high);
}

// Both triangles of one cell whose bounding boxes are single 2×2 tiles (what a warp close to the
// identity gives nearly everywhere): the upper triangle's tile in lanes 0–3, the lower one's in
// lanes 4–7, each lane doing cover's operations. The z-tests then run upper before lower, as
// in the scalar order. Only called where the CPU has AVX.
__attribute__((target("avx"))) void cover_cell_avx(const WarpedVertex* top, const WarpedVertex* bottom,
                                                   const TriangleSetup& tu, const TriangleSetup& tl, int width,
                                                   ZBuffer& target) {
  const WarpedVertex &ua = top[0], &ub = top[1], &uc = bottom[0];  // the cell's triangles, as rasterise_row
  const WarpedVertex &la = top[1], &lb = bottom[1], &lc = bottom[0];
  const __m256 inclusive = _mm256_set1_ps(kInclusive);
  const __m256 one = _mm256_set1_ps(1.f);
  const __m256 inv_area = halves(tu.inv_area, tl.inv_area);
  const __m256 bc_u = halves(uc.u - ub.u, lc.u - lb.u), bc_v = halves(uc.v - ub.v, lc.v - lb.v);
  const __m256 ca_u = halves(ua.u - uc.u, la.u - lc.u), ca_v = halves(ua.v - uc.v, la.v - lc.v);
  const __m256 b_u = halves(ub.u, lb.u), b_v = halves(ub.v, lb.v);
  const __m256 c_u = halves(uc.u, lc.u), c_v = halves(uc.v, lc.v);
  const __m256 a_z = halves(ua.z, la.z), b_z = halves(ub.z, lb.z), c_z = halves(uc.z, lc.z);
  const __m256 px = _mm256_add_ps(halves(static_cast<float>(tu.x0), static_cast<float>(tl.x0)),
                                  _mm256_setr_ps(0.f, 1.f, 0.f, 1.f, 0.f, 1.f, 0.f, 1.f));
  const __m256 py = _mm256_add_ps(halves(static_cast<float>(tu.y0), static_cast<float>(tl.y0)),
                                  _mm256_setr_ps(0.f, 0.f, 1.f, 1.f, 0.f, 0.f, 1.f, 1.f));
  const __m256 w0 = _mm256_mul_ps(
      _mm256_sub_ps(_mm256_mul_ps(bc_u, _mm256_sub_ps(py, b_v)), _mm256_mul_ps(bc_v, _mm256_sub_ps(px, b_u))), inv_area);
  const __m256 w1 = _mm256_mul_ps(
      _mm256_sub_ps(_mm256_mul_ps(ca_u, _mm256_sub_ps(py, c_v)), _mm256_mul_ps(ca_v, _mm256_sub_ps(px, c_u))), inv_area);
  const __m256 w2 = _mm256_sub_ps(_mm256_sub_ps(one, w0), w1);
  const __m256 outside = _mm256_or_ps(
      _mm256_or_ps(_mm256_cmp_ps(w0, inclusive, _CMP_LT_OQ), _mm256_cmp_ps(w1, inclusive, _CMP_LT_OQ)),
      _mm256_cmp_ps(w2, inclusive, _CMP_LT_OQ));
  const __m256 in_box =
      _mm256_and_ps(_mm256_cmp_ps(px, halves(static_cast<float>(tu.x1), static_cast<float>(tl.x1)), _CMP_LE_OQ),
                    _mm256_cmp_ps(py, halves(static_cast<float>(tu.y1), static_cast<float>(tl.y1)), _CMP_LE_OQ));
  const __m256 lane_inside = _mm256_andnot_ps(outside, in_box);
  const int inside = _mm256_movemask_ps(lane_inside);
  if (inside == 0) return;
  // Lanes outside test +inf against the upper tile's first pixel, which lies in its box: eight
  // z-tests as selects, without the branches whose outcome noisy depth makes unpredictable.
  alignas(32) float z[8];
  const __m256 z_inside = _mm256_div_ps(
      one, _mm256_add_ps(_mm256_add_ps(_mm256_div_ps(w0, a_z), _mm256_div_ps(w1, b_z)), _mm256_div_ps(w2, c_z)));
  _mm256_store_ps(z, _mm256_blendv_ps(_mm256_set1_ps(kFar), z_inside, lane_inside));
  const std::size_t stride = static_cast<std::size_t>(width);
  const std::size_t base[2] = {static_cast<std::size_t>(tu.y0) * stride + static_cast<std::size_t>(tu.x0),
                               static_cast<std::size_t>(tl.y0) * stride + static_cast<std::size_t>(tl.x0)};
  const float weight[2] = {tu.weight, tl.weight};
  for (int lane = 0; lane < 8; ++lane) {
    const std::size_t index = (inside >> lane & 1) != 0 ? base[lane >> 2] + static_cast<std::size_t>(lane & 1) +
                                                              static_cast<std::size_t>(lane >> 1 & 1) * stride
                                                        : base[0];
    const __m128 z_new = _mm_set_ss(z[lane]);
    const __m128 z_old = _mm_load_ss(&target.z[index]);
    const __m128 wins = _mm_cmplt_ss(z_new, z_old);
    _mm_store_ss(&target.z[index], _mm_min_ss(z_new, z_old));  // z < old ? z : old
    _mm_store_ss(&target.weight[index],
                 _mm_blendv_ps(_mm_load_ss(&target.weight[index]), _mm_set_ss(weight[lane >> 2]), wins));
  }
}

#endif

// Both triangles of every cell between source rows `top` and `bottom`, in the scalar order
// (cell by cell, upper-left triangle first), so that ties of the z-test resolve the same way.
void rasterise_row(const WarpedVertex* top, const WarpedVertex* bottom, int width, int height,
                   const DepthWarpMergeOptions& options, ZBuffer& target) {
  int c = 0;
#if defined(__SSE2__)
  static const bool has_avx = __builtin_cpu_supports("avx");
  for (; c + 4 < width; c += 4) {
    const Lanes t0 = load_lanes(top + c), t1 = load_lanes(top + c + 1);
    const Lanes b0 = load_lanes(bottom + c), b1 = load_lanes(bottom + c + 1);
    SetupLanes upper, lower;
    set_up_lanes(t0, t1, b0, width, height, options, upper);
    set_up_lanes(t1, b1, b0, width, height, options, lower);
    if ((upper.accepted | upper.wild | lower.accepted | lower.wild) == 0) continue;
    for (int i = 0; i < 4; ++i) {
      const int x = c + i;
      if (has_avx && (upper.accepted & lower.accepted) >> i & 1) {
        const TriangleSetup tu = lane(upper, i), tl = lane(lower, i);
        if (single_tile(tu) && single_tile(tl)) {
          cover_cell_avx(top + x, bottom + x, tu, tl, width, target);
          continue;
        }
      }
      if (upper.wild >> i & 1) {
        rasterise(top[x], top[x + 1], bottom[x], width, height, options, target);
      } else if (upper.accepted >> i & 1) {
        cover(top[x], top[x + 1], bottom[x], lane(upper, i), width, target);
      }
      if (lower.wild >> i & 1) {
        rasterise(top[x + 1], bottom[x + 1], bottom[x], width, height, options, target);
      } else if (lower.accepted >> i & 1) {
        cover(top[x + 1], bottom[x + 1], bottom[x], lane(lower, i), width, target);
      }
    }
  }
#endif
  for (; c + 1 < width; ++c) {
    rasterise(top[c], top[c + 1], bottom[c], width, height, options, target);
    rasterise(top[c + 1], bottom[c + 1], bottom[c], width, height, options, target);
  }
}

double axial_sigma(double z) { return 0.0012 + 0.0019 * (z - 0.4) * (z - 0.4); }

#if defined(__SSE2__)
// merge_depth's rules for four pixels with history, as selects; every lane performs the scalar
// operations in their order (σ_z in double precision, as axial_sigma), so the bits are the same.
void merge_four(const float* depth, const float* warped, const float* warped_weight,
                const DepthWarpMergeOptions& options, float* merged, float* merged_weight) {
  const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.f);
  const __m128 d = _mm_loadu_ps(depth), d_w = _mm_loadu_ps(warped), w = _mm_loadu_ps(warped_weight);
  const __m128 new_valid = _mm_and_ps(_mm_cmpgt_ps(d, zero), _mm_cmple_ps(d, _mm_set1_ps(3.4e38f)));
  const __m128 old_valid = _mm_and_ps(_mm_cmpgt_ps(d_w, zero), _mm_cmpgt_ps(w, zero));
  const auto sigma = [](__m128d z) {
    const __m128d offset = _mm_sub_pd(z, _mm_set1_pd(0.4));
    return _mm_add_pd(_mm_set1_pd(0.0012), _mm_mul_pd(_mm_mul_pd(_mm_set1_pd(0.0019), offset), offset));
  };
  const __m128 sigma_d = _mm_movelh_ps(_mm_cvtpd_ps(sigma(_mm_cvtps_pd(d))),
                                       _mm_cvtpd_ps(sigma(_mm_cvtps_pd(_mm_movehl_ps(d, d)))));
  const __m128 tau = _mm_add_ps(_mm_set1_ps(options.merge_threshold_m), _mm_mul_ps(_mm_set1_ps(3.f), sigma_d));
  const __m128 close = _mm_cmple_ps(_mm_andnot_ps(_mm_set1_ps(-0.f), _mm_sub_ps(d, d_w)), tau);
  const __m128 w_plus = _mm_add_ps(w, one);
  const __m128 average = _mm_div_ps(_mm_add_ps(_mm_mul_ps(w, d_w), d), w_plus);
  // _mm_min_ps(a, b) is "a < b ? a : b", std::min(a, b) is "b < a ? b : a".
  const __m128 capped = _mm_min_ps(_mm_set1_ps(options.max_weight), w_plus);
  const __m128 both = _mm_and_ps(new_valid, old_valid);
  const __m128 fuse = _mm_and_ps(both, close);
  const __m128 fade = _mm_andnot_ps(new_valid, _mm_and_ps(old_valid, _mm_cmpgt_ps(w, one)));
  // Priority: fuse, then any new depth (weight 1), then the fading history.
  __m128 out = _mm_and_ps(fade, d_w), out_weight = _mm_and_ps(fade, _mm_sub_ps(w, one));
  out = _mm_or_ps(_mm_and_ps(new_valid, d), _mm_andnot_ps(new_valid, out));
  out_weight = _mm_or_ps(_mm_and_ps(new_valid, one), _mm_andnot_ps(new_valid, out_weight));
  out = _mm_or_ps(_mm_and_ps(fuse, average), _mm_andnot_ps(fuse, out));
  out_weight = _mm_or_ps(_mm_and_ps(fuse, capped), _mm_andnot_ps(fuse, out_weight));
  _mm_storeu_ps(merged, out);
  _mm_storeu_ps(merged_weight, out_weight);
}
#endif

}  // namespace

void warp_depth(const DepthMap& previous_depth, const DepthWeightMap& previous_weight,
                const PinholeIntrinsics& intrinsics, const Pose& current_from_prev,
                const DepthWarpMergeOptions& options, DepthMap& warped, DepthWeightMap& warped_weight) {
  const int width = previous_depth.width();
  const int height = previous_depth.height();
  const std::size_t pixels = previous_depth.size();
  warped.resize(width, height);
  warped_weight.resize(width, height);
  if (pixels == 0) return;
  const bool has_weight = previous_weight.same_shape(previous_depth);

  float m[3][4];
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) m[r][c] = static_cast<float>(current_from_prev.matrix()(r, c));
  }
  const float fx = static_cast<float>(intrinsics.fx), fy = static_cast<float>(intrinsics.fy);
  const float cx = static_cast<float>(intrinsics.cx), cy = static_cast<float>(intrinsics.cy);
  thread_local WarpScratch scratch;  // warp_depth does not call itself, so one per calling thread suffices
  std::vector<WarpedVertex>& vertices = scratch.vertices;
  vertices.resize(pixels);
  parallel_rows(height, options.threads, [&](int begin, int end) {
    for (int r = begin; r < end; ++r) {
      int c = 0;
#if defined(__SSE2__)
      // Four vertices at a time with the scalar loop's operations in its order (same bits); a
      // vertex without depth, or behind the current camera, is all zeros.
      const float* depth_row = previous_depth.row(r).data();
      const float* weight_row = has_weight ? previous_weight.row(r).data() : nullptr;
      const __m128 y_dir = _mm_set1_ps((static_cast<float>(r) - cy) / fy);
      const __m128 zero = _mm_setzero_ps();
      for (; c + 4 <= width; c += 4) {
        const __m128 z = _mm_loadu_ps(depth_row + c);
        const __m128 x_dir = _mm_div_ps(
            _mm_sub_ps(_mm_cvtepi32_ps(_mm_add_epi32(_mm_set1_epi32(c), _mm_setr_epi32(0, 1, 2, 3))), _mm_set1_ps(cx)),
            _mm_set1_ps(fx));
        const __m128 x = _mm_mul_ps(x_dir, z), y = _mm_mul_ps(y_dir, z);
        __m128 p[3];
        for (int k = 0; k < 3; ++k) {
          p[k] = _mm_add_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_set1_ps(m[k][0]), x), _mm_mul_ps(_mm_set1_ps(m[k][1]), y)),
                                       _mm_mul_ps(_mm_set1_ps(m[k][2]), z)),
                            _mm_set1_ps(m[k][3]));
        }
        const __m128 valid = _mm_and_ps(_mm_and_ps(_mm_cmpgt_ps(z, zero), _mm_cmple_ps(z, _mm_set1_ps(3.4e38f))),
                                        _mm_cmpgt_ps(p[2], zero));
        __m128 u = _mm_and_ps(valid, _mm_add_ps(_mm_div_ps(_mm_mul_ps(_mm_set1_ps(fx), p[0]), p[2]), _mm_set1_ps(cx)));
        __m128 v = _mm_and_ps(valid, _mm_add_ps(_mm_div_ps(_mm_mul_ps(_mm_set1_ps(fy), p[1]), p[2]), _mm_set1_ps(cy)));
        __m128 depth = _mm_and_ps(valid, p[2]);
        __m128 weight = _mm_and_ps(valid, weight_row ? _mm_loadu_ps(weight_row + c) : _mm_set1_ps(1.f));
        _MM_TRANSPOSE4_PS(u, v, depth, weight);
        float* out = &vertices[static_cast<std::size_t>(r) * static_cast<std::size_t>(width) + static_cast<std::size_t>(c)].u;
        _mm_storeu_ps(out, u);
        _mm_storeu_ps(out + 4, v);
        _mm_storeu_ps(out + 8, depth);
        _mm_storeu_ps(out + 12, weight);
      }
#endif
      for (; c < width; ++c) {
        const float z = previous_depth(r, c);
        WarpedVertex& vertex = vertices[static_cast<std::size_t>(r) * static_cast<std::size_t>(width) + static_cast<std::size_t>(c)];
        if (!(z > 0.f && z <= 3.4e38f)) {
          vertex = {};
          continue;
        }
        const float x = (static_cast<float>(c) - cx) / fx * z;  // φ⁻¹, previous camera frame
        const float y = (static_cast<float>(r) - cy) / fy * z;
        const float px = m[0][0] * x + m[0][1] * y + m[0][2] * z + m[0][3];
        const float py = m[1][0] * x + m[1][1] * y + m[1][2] * z + m[1][3];
        const float pz = m[2][0] * x + m[2][1] * y + m[2][2] * z + m[2][3];
        if (!(pz > 0.f)) {
          vertex = {};
          continue;
        }
        vertex = {fx * px / pz + cx, fy * py / pz + cy, pz, has_weight ? previous_weight(r, c) : 1.f};
      }
    }
  });

  const int bands = std::max(1, std::min(worker_count(options.threads), (height - 1) / 64));
  std::vector<ZBuffer>& buffers = scratch.buffers;
  if (buffers.size() < static_cast<std::size_t>(bands)) buffers.resize(static_cast<std::size_t>(bands));
  parallel_rows(
      bands, bands,
      [&](int band_begin, int band_end) {
        for (int band = band_begin; band < band_end; ++band) {
          const int row_begin = static_cast<int>(static_cast<long long>(height - 1) * band / bands);
          const int row_end = static_cast<int>(static_cast<long long>(height - 1) * (band + 1) / bands);
          ZBuffer& target = buffers[static_cast<std::size_t>(band)];
          target.z.assign(pixels, kFar);
          target.weight.resize(pixels);  // read only where z was written
          for (int r = row_begin; r < row_end; ++r) {
            const WarpedVertex* top = &vertices[static_cast<std::size_t>(r) * static_cast<std::size_t>(width)];
            rasterise_row(top, top + width, width, height, options, target);
          }
        }
      },
      1);

  parallel_rows(height, options.threads, [&](int begin, int end) {
    const std::size_t first = static_cast<std::size_t>(begin) * static_cast<std::size_t>(width);
    const std::size_t last = static_cast<std::size_t>(end) * static_cast<std::size_t>(width);
    for (std::size_t i = first; i < last; ++i) {
      float z = buffers[0].z[i];
      float weight = buffers[0].weight[i];
      for (std::size_t b = 1; b < static_cast<std::size_t>(bands); ++b) {
        if (buffers[b].z[i] < z) {
          z = buffers[b].z[i];
          weight = buffers[b].weight[i];
        }
      }
      const bool covered = z < kFar;
      warped.pixels()[i] = covered ? z : 0.f;
      warped_weight.pixels()[i] = covered ? weight : 0.f;
    }
  });
}

void merge_depth(const DepthMap& depth, const DepthMap& warped, const DepthWeightMap& warped_weight,
                 const DepthWarpMergeOptions& options, DepthMap& merged, DepthWeightMap& merged_weight) {
  merged.resize(depth.width(), depth.height());
  merged_weight.resize(depth.width(), depth.height());
  const bool has_history = warped.same_shape(depth) && warped_weight.same_shape(depth);
  const std::size_t width = static_cast<std::size_t>(depth.width());
  parallel_rows(depth.height(), options.threads, [&](int begin, int end) {
    std::size_t i = static_cast<std::size_t>(begin) * width;
#if defined(__SSE2__)
    if (has_history) {
      for (; i + 4 <= static_cast<std::size_t>(end) * width; i += 4) {
        merge_four(depth.pixels().data() + i, warped.pixels().data() + i, warped_weight.pixels().data() + i, options,
                   merged.pixels().data() + i, merged_weight.pixels().data() + i);
      }
    }
#endif
    for (; i < static_cast<std::size_t>(end) * width; ++i) {
      const float d = depth.pixels()[i];
      const bool new_valid = d > 0.f && d <= 3.4e38f;
      const float d_w = has_history ? warped.pixels()[i] : 0.f;
      const float w = has_history ? warped_weight.pixels()[i] : 0.f;
      const bool old_valid = d_w > 0.f && w > 0.f;
      float out = 0.f, out_weight = 0.f;
      if (new_valid && old_valid) {
        const float tau = options.merge_threshold_m + 3.f * static_cast<float>(axial_sigma(d));
        if (std::fabs(d - d_w) <= tau) {
          out = (w * d_w + d) / (w + 1.f);
          out_weight = std::min(w + 1.f, options.max_weight);
        } else {
          out = d;
          out_weight = 1.f;
        }
      } else if (new_valid) {
        out = d;
        out_weight = 1.f;
      } else if (old_valid && w > 1.f) {
        out = d_w;
        out_weight = w - 1.f;
      }
      merged.pixels()[i] = out;
      merged_weight.pixels()[i] = out_weight;
    }
  });
}

void DepthWarpMergeStageBase::declare(StageBuilder& builder) {
  depth_ = builder.read(kDepth);
  frame_ = builder.read(kFrame);
  previous_depth_ = builder.read_previous(kDepthFiltered);
  previous_weight_ = builder.read_previous(kDepthWeight);
  previous_frame_ = builder.read_previous(kFrame);
  filtered_ = builder.write(kDepthFiltered);
  weight_ = builder.write(kDepthWeight);
}

Pose DepthWarpMergeStageBase::current_from_previous(StageContext& context) {
  const FrameInfo& frame = context.get(frame_);
  const FrameInfo* previous_frame = context.get(previous_frame_);
  const Pose current = frame.camera_to_world.value_or(Pose::Identity());
  const Pose previous =
      previous_frame && previous_frame->camera_to_world ? *previous_frame->camera_to_world : Pose::Identity();
  return current.inverse() * previous;
}

void DepthWarpMergeCpuStage::run(StageContext& context) {
  const DepthMap* previous_depth = context.get(previous_depth_);
  const DepthWeightMap* previous_weight = context.get(previous_weight_);
  const DepthMap& depth = context.get(depth_);
  if (previous_depth && previous_weight && previous_depth->same_shape(depth)) {
    warp_depth(*previous_depth, *previous_weight, context.get(frame_).intrinsics, current_from_previous(context),
               options(), warped_, warped_weight_);
  } else {
    warped_.resize(0, 0);
    warped_weight_.resize(0, 0);
  }
  merge_depth(depth, warped_, warped_weight_, options(), context.get(filtered_), context.get(weight_));
}

}  // namespace relight::reconstruct
