// CPU implementation of positions_from_depth / normals_from_positions (definitions in
// normals_from_positions.h). Rows are split over threads; every pixel depends only on its inputs.
#include "relight/reconstruct/normals_from_positions.h"

#include <algorithm>
#include <cmath>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "relight/core/parallel.h"

namespace relight::reconstruct {

namespace {

Float3 cross(const Float3& a, const Float3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

// A neighbour continues the surface when it has a position and its depth is close to the centre's.
bool continues(const Float3& centre, const Float3& neighbour, float max_jump_rel) {
  return neighbour.z > 0.f && std::fabs(neighbour.z - centre.z) <= max_jump_rel * centre.z;
}

// Difference vector along one axis: central (when asked for) if both sides continue, else forward
// if possible, else backward; false when neither exists.
bool difference(const Float3* forward, const Float3* backward, const Float3& centre, float max_jump_rel, bool centred,
                Float3& out) {
  const bool forward_ok = forward && continues(centre, *forward, max_jump_rel);
  const bool backward_ok = backward && continues(centre, *backward, max_jump_rel);
  if (forward_ok && backward_ok && centred) {
    out = *forward - *backward;
    return true;
  }
  if (forward_ok) {
    out = *forward - centre;
    return true;
  }
  if (backward_ok) {
    out = centre - *backward;
    return true;
  }
  return false;
}

#if defined(__SSE2__)
struct Float3x4 {
  __m128 x, y, z;
};

// Four consecutive Float3 (12 floats) as x, y and z lanes.
Float3x4 load4(const Float3* p) {
  static_assert(sizeof(Float3) == 3 * sizeof(float));
  const float* f = &p->x;
  const __m128 a = _mm_loadu_ps(f), b = _mm_loadu_ps(f + 4), c = _mm_loadu_ps(f + 8);
  const __m128 x = _mm_shuffle_ps(a, _mm_shuffle_ps(b, c, _MM_SHUFFLE(1, 1, 2, 2)), _MM_SHUFFLE(2, 0, 3, 0));
  const __m128 y = _mm_shuffle_ps(_mm_shuffle_ps(a, b, _MM_SHUFFLE(0, 0, 1, 1)),
                                  _mm_shuffle_ps(b, c, _MM_SHUFFLE(2, 2, 3, 3)), _MM_SHUFFLE(2, 0, 2, 0));
  const __m128 z = _mm_shuffle_ps(_mm_shuffle_ps(a, b, _MM_SHUFFLE(1, 1, 2, 2)),
                                  _mm_shuffle_ps(c, c, _MM_SHUFFLE(3, 3, 0, 0)), _MM_SHUFFLE(2, 0, 2, 0));
  return {x, y, z};
}

__m128 pick(__m128 mask, __m128 if_set, __m128 if_clear) {
  return _mm_or_ps(_mm_and_ps(mask, if_set), _mm_andnot_ps(mask, if_clear));
}

Float3x4 pick(__m128 mask, const Float3x4& if_set, const Float3x4& if_clear) {
  return {pick(mask, if_set.x, if_clear.x), pick(mask, if_set.y, if_clear.y), pick(mask, if_set.z, if_clear.z)};
}

Float3x4 minus(const Float3x4& a, const Float3x4& b) {
  return {_mm_sub_ps(a.x, b.x), _mm_sub_ps(a.y, b.y), _mm_sub_ps(a.z, b.z)};
}

__m128 continues4(const Float3x4& centre, const Float3x4& neighbour, __m128 max_jump_rel) {
  const __m128 jump = _mm_andnot_ps(_mm_set1_ps(-0.f), _mm_sub_ps(neighbour.z, centre.z));
  return _mm_and_ps(_mm_cmpgt_ps(neighbour.z, _mm_setzero_ps()), _mm_cmple_ps(jump, _mm_mul_ps(max_jump_rel, centre.z)));
}

// The scalar pixel's rules for columns c..c+3, all of which have both column neighbours; a row
// neighbour that does not exist is passed as nullptr. Same operations in the same order, hence
// the same bits.
void normals_of_four(const Float3* row, const Float3* below, const Float3* above, int c, int s, float max_jump_rel,
                     bool centred, Float3* out) {
  const __m128 jump_rel = _mm_set1_ps(max_jump_rel);
  const __m128 none = _mm_setzero_ps();
  const Float3x4 p = load4(row + c);
  const Float3x4 right = load4(row + c + s), left = load4(row + c - s);
  const __m128 right_ok = continues4(p, right, jump_rel), left_ok = continues4(p, left, jump_rel);
  const __m128 centred_mask = _mm_castsi128_ps(_mm_set1_epi32(centred ? -1 : 0));
  const __m128 col_both = _mm_and_ps(centred_mask, _mm_and_ps(right_ok, left_ok));
  const Float3x4 d_col = pick(col_both, minus(right, left), pick(right_ok, minus(right, p), minus(p, left)));
  const Float3x4 down = load4(below ? below + c : row + c), up = load4(above ? above + c : row + c);
  const __m128 down_ok = below ? continues4(p, down, jump_rel) : none;
  const __m128 up_ok = above ? continues4(p, up, jump_rel) : none;
  const __m128 row_both = _mm_and_ps(centred_mask, _mm_and_ps(down_ok, up_ok));
  const Float3x4 d_row = pick(row_both, minus(down, up), pick(down_ok, minus(down, p), minus(p, up)));
  const Float3x4 n = {_mm_sub_ps(_mm_mul_ps(d_col.y, d_row.z), _mm_mul_ps(d_col.z, d_row.y)),
                      _mm_sub_ps(_mm_mul_ps(d_col.z, d_row.x), _mm_mul_ps(d_col.x, d_row.z)),
                      _mm_sub_ps(_mm_mul_ps(d_col.x, d_row.y), _mm_mul_ps(d_col.y, d_row.x))};
  const __m128 len =
      _mm_sqrt_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(n.x, n.x), _mm_mul_ps(n.y, n.y)), _mm_mul_ps(n.z, n.z)));
  const __m128 facing_away = _mm_cmpgt_ps(
      _mm_add_ps(_mm_add_ps(_mm_mul_ps(n.x, p.x), _mm_mul_ps(n.y, p.y)), _mm_mul_ps(n.z, p.z)), none);
  const __m128 scale = _mm_div_ps(pick(facing_away, _mm_set1_ps(-1.f), _mm_set1_ps(1.f)), len);
  const __m128 valid = _mm_and_ps(_mm_and_ps(_mm_cmpnle_ps(p.z, none), _mm_or_ps(right_ok, left_ok)),
                                  _mm_and_ps(_mm_or_ps(down_ok, up_ok), _mm_cmpgt_ps(len, none)));
  alignas(16) float x[4], y[4], z[4];
  _mm_store_ps(x, _mm_and_ps(valid, _mm_mul_ps(scale, n.x)));
  _mm_store_ps(y, _mm_and_ps(valid, _mm_mul_ps(scale, n.y)));
  _mm_store_ps(z, _mm_and_ps(valid, _mm_mul_ps(scale, n.z)));
  for (int i = 0; i < 4; ++i) out[c + i] = {x[i], y[i], z[i]};
}
#endif

}  // namespace

void positions_from_depth(const DepthMap& depth, const PinholeIntrinsics& intrinsics, PositionMap& positions,
                          int threads) {
  positions.resize(depth.width(), depth.height());
  const float inv_fx = static_cast<float>(1.0 / intrinsics.fx);
  const float inv_fy = static_cast<float>(1.0 / intrinsics.fy);
  const float cx = static_cast<float>(intrinsics.cx);
  const float cy = static_cast<float>(intrinsics.cy);
  parallel_rows(depth.height(), threads, [&](int begin, int end) {
    for (int r = begin; r < end; ++r) {
      const float* z_row = depth.row(r).data();
      Float3* out = positions.row(r).data();
      const float y_scale = (static_cast<float>(r) - cy) * inv_fy;
      for (int c = 0; c < depth.width(); ++c) {
        const float z = z_row[c];
        const bool valid = z > 0.f && z <= 3.4e38f;  // is_valid_depth without the libm call
        const float zv = valid ? z : 0.f;
        out[c] = {(static_cast<float>(c) - cx) * inv_fx * zv, y_scale * zv, zv};
      }
    }
  });
}

void normals_from_positions(const PositionMap& positions, NormalMap& normals, const CrossNormalOptions& options) {
  const int width = positions.width();
  const int height = positions.height();
  const int s = options.stride;
  normals.resize(width, height);
  parallel_rows(height, options.threads, [&](int begin, int end) {
    for (int r = begin; r < end; ++r) {
      const Float3* row = positions.row(r).data();
      const Float3* below = r + s < height ? positions.row(r + s).data() : nullptr;
      const Float3* above = r - s >= 0 ? positions.row(r - s).data() : nullptr;
      Float3* out = normals.row(r).data();
      const auto pixel = [&](int c) {
        const Float3& p = row[c];
        out[c] = {};
        if (p.z <= 0.f) return;
        Float3 d_col, d_row;
        if (!difference(c + s < width ? &row[c + s] : nullptr, c - s >= 0 ? &row[c - s] : nullptr, p,
                        options.max_jump_rel, options.centred, d_col)) {
          return;
        }
        if (!difference(below ? &below[c] : nullptr, above ? &above[c] : nullptr, p, options.max_jump_rel,
                        options.centred, d_row)) {
          return;
        }
        Float3 n = cross(d_col, d_row);
        const float len = length(n);
        if (!(len > 0.f)) return;
        n = ((dot(n, p) > 0.f ? -1.f : 1.f) / len) * n;  // towards the camera
        out[c] = n;
      };
      int c = 0;
      for (; c < std::min(s, width); ++c) pixel(c);
#if defined(__SSE2__)
      for (; c + 3 + s < width; c += 4) normals_of_four(row, below, above, c, s, options.max_jump_rel, options.centred, out);
#endif
      for (; c < width; ++c) pixel(c);
    }
  });
}

void NormalsFromPositionsCpuStage::declare(StageBuilder& builder) {
  depth_ = builder.read(buffers_.depth);
  frame_ = builder.read(buffers_.frame);
  positions_ = builder.write(buffers_.positions);
  normals_ = builder.write(buffers_.normals);
}

void NormalsFromPositionsCpuStage::run(StageContext& context) {
  PositionMap& positions = context.get(positions_);
  positions_from_depth(context.get(depth_), context.get(frame_).intrinsics, positions, options_.threads);
  normals_from_positions(positions, context.get(normals_), options_);
}

}  // namespace relight::reconstruct
