// CPU implementation of positions_from_depth / normals_from_positions (definitions in
// normals_from_positions.h). Rows are split over threads; every pixel depends only on its inputs.
#include "relight/reconstruct/normals_from_positions.h"

#include <cmath>

#include "relight/core/parallel.h"

namespace relight {

namespace {

Float3 cross(const Float3& a, const Float3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

// A neighbour continues the surface when it has a position and its depth is close to the centre's.
bool continues(const Float3& centre, const Float3& neighbour, float max_jump_rel) {
  return neighbour.z > 0.f && std::fabs(neighbour.z - centre.z) <= max_jump_rel * centre.z;
}

// Difference vector along one axis: forward if possible, else backward; false when neither exists.
bool difference(const Float3* forward, const Float3* backward, const Float3& centre, float max_jump_rel,
                Float3& out) {
  if (forward && continues(centre, *forward, max_jump_rel)) {
    out = *forward - centre;
    return true;
  }
  if (backward && continues(centre, *backward, max_jump_rel)) {
    out = centre - *backward;
    return true;
  }
  return false;
}

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
      for (int c = 0; c < width; ++c) {
        const Float3& p = row[c];
        out[c] = {};
        if (p.z <= 0.f) continue;
        Float3 d_col, d_row;
        if (!difference(c + s < width ? &row[c + s] : nullptr, c - s >= 0 ? &row[c - s] : nullptr, p,
                        options.max_jump_rel, d_col)) {
          continue;
        }
        if (!difference(below ? &below[c] : nullptr, above ? &above[c] : nullptr, p, options.max_jump_rel, d_row)) {
          continue;
        }
        Float3 n = cross(d_col, d_row);
        const float len = length(n);
        if (!(len > 0.f)) continue;
        n = ((dot(n, p) > 0.f ? -1.f : 1.f) / len) * n;  // towards the camera
        out[c] = n;
      }
    }
  });
}

void NormalsFromPositionsCpuStage::declare(StageBuilder& builder) {
  depth_ = builder.read<DepthMap>(buffers_.depth);
  frame_ = builder.read<FrameInfo>(buffers_.frame);
  positions_ = builder.write<PositionMap>(buffers_.positions);
  normals_ = builder.write<NormalMap>(buffers_.normals);
}

void NormalsFromPositionsCpuStage::run(StageContext& context) {
  PositionMap& positions = context.get(positions_);
  positions_from_depth(context.get(depth_), context.get(frame_).intrinsics, positions, options_.threads);
  normals_from_positions(positions, context.get(normals_), options_);
}

}  // namespace relight
