// CPU reference rasteriser and merge of method 2 (definition in depth_warp_merge.h). The source
// rows are split into bands; each band rasterises into its own z-buffer and the bands are
// combined with the same z-test, so the result does not depend on the thread count.
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "relight/core/parallel.h"
#include "relight/reconstruct/depth_warp_merge.h"

namespace relight {

namespace {

constexpr float kFar = std::numeric_limits<float>::infinity();

struct WarpedVertex {
  float u = 0.f, v = 0.f, z = 0.f;  // z <= 0: no vertex
  float weight = 0.f;
};

struct ZBuffer {
  std::vector<float> z;
  std::vector<float> weight;
  ZBuffer(std::size_t pixels) : z(pixels, kFar), weight(pixels, 0.f) {}
};

float edge(float ax, float ay, float bx, float by, float px, float py) {
  return (bx - ax) * (py - ay) - (by - ay) * (px - ax);
}

void rasterise(const WarpedVertex& a, const WarpedVertex& b, const WarpedVertex& c, int width, int height,
               const DepthWarpMergeOptions& options, ZBuffer& target) {
  if (!(a.z > 0.f && b.z > 0.f && c.z > 0.f)) return;
  const float z_min = std::min({a.z, b.z, c.z});
  const float z_max = std::max({a.z, b.z, c.z});
  if (z_max - z_min > options.max_edge_m + options.max_edge_rel * z_min) return;  // across a discontinuity
  const float area = edge(a.u, a.v, b.u, b.v, c.u, c.v);
  if (std::fabs(area) < 1e-8f) return;
  // The bounding box is widened by a rounding margin: a vertex that φ(φ⁻¹(·)) maps to 2.0000002
  // must still cover pixel centre 2.
  constexpr float margin = 1e-3f;
  const int x0 = std::max(0, static_cast<int>(std::ceil(std::min({a.u, b.u, c.u}) - margin)));
  const int x1 = std::min(width - 1, static_cast<int>(std::floor(std::max({a.u, b.u, c.u}) + margin)));
  const int y0 = std::max(0, static_cast<int>(std::ceil(std::min({a.v, b.v, c.v}) - margin)));
  const int y1 = std::min(height - 1, static_cast<int>(std::floor(std::max({a.v, b.v, c.v}) + margin)));
  const float inv_area = 1.f / area;
  const float weight = std::min({a.weight, b.weight, c.weight});
  constexpr float inclusive = -1e-4f;  // pixel centres on a shared edge belong to both triangles
  for (int y = y0; y <= y1; ++y) {
    const float py = static_cast<float>(y);
    for (int x = x0; x <= x1; ++x) {
      const float px = static_cast<float>(x);
      const float w0 = edge(b.u, b.v, c.u, c.v, px, py) * inv_area;
      const float w1 = edge(c.u, c.v, a.u, a.v, px, py) * inv_area;
      const float w2 = 1.f - w0 - w1;
      if (w0 < inclusive || w1 < inclusive || w2 < inclusive) continue;
      const float z = 1.f / (w0 / a.z + w1 / b.z + w2 / c.z);  // 1/z is affine in screen space
      const std::size_t index = static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x);
      if (z < target.z[index]) {
        target.z[index] = z;
        target.weight[index] = weight;
      }
    }
  }
}

double axial_sigma(double z) { return 0.0012 + 0.0019 * (z - 0.4) * (z - 0.4); }

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
  std::vector<WarpedVertex> vertices(pixels);
  parallel_rows(height, options.threads, [&](int begin, int end) {
    for (int r = begin; r < end; ++r) {
      for (int c = 0; c < width; ++c) {
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
  std::vector<ZBuffer> buffers(static_cast<std::size_t>(bands), ZBuffer(pixels));
  parallel_rows(
      bands, bands,
      [&](int band_begin, int band_end) {
        for (int band = band_begin; band < band_end; ++band) {
          const int row_begin = static_cast<int>(static_cast<long long>(height - 1) * band / bands);
          const int row_end = static_cast<int>(static_cast<long long>(height - 1) * (band + 1) / bands);
          ZBuffer& target = buffers[static_cast<std::size_t>(band)];
          for (int r = row_begin; r < row_end; ++r) {
            const WarpedVertex* top = &vertices[static_cast<std::size_t>(r) * static_cast<std::size_t>(width)];
            const WarpedVertex* bottom = top + width;
            for (int c = 0; c + 1 < width; ++c) {
              rasterise(top[c], top[c + 1], bottom[c], width, height, options, target);
              rasterise(top[c + 1], bottom[c + 1], bottom[c], width, height, options, target);
            }
          }
        }
      },
      1);

  for (std::size_t i = 0; i < pixels; ++i) {
    float z = buffers[0].z[i];
    float weight = buffers[0].weight[i];
    for (std::size_t b = 1; b < buffers.size(); ++b) {
      if (buffers[b].z[i] < z) {
        z = buffers[b].z[i];
        weight = buffers[b].weight[i];
      }
    }
    const bool covered = z < kFar;
    warped.pixels()[i] = covered ? z : 0.f;
    warped_weight.pixels()[i] = covered ? weight : 0.f;
  }
}

void merge_depth(const DepthMap& depth, const DepthMap& warped, const DepthWeightMap& warped_weight,
                 const DepthWarpMergeOptions& options, DepthMap& merged, DepthWeightMap& merged_weight) {
  merged.resize(depth.width(), depth.height());
  merged_weight.resize(depth.width(), depth.height());
  const bool has_history = warped.same_shape(depth) && warped_weight.same_shape(depth);
  for (std::size_t i = 0; i < depth.size(); ++i) {
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
}

void DepthWarpMergeCpuStage::declare(StageBuilder& builder) {
  depth_ = builder.read<DepthMap>("depth");
  frame_ = builder.read<FrameInfo>("frame");
  previous_depth_ = builder.read_previous<DepthMap>("depth_filtered");
  previous_weight_ = builder.read_previous<DepthWeightMap>("depth_weight");
  previous_frame_ = builder.read_previous<FrameInfo>("frame");
  filtered_ = builder.write<DepthMap>("depth_filtered");
  weight_ = builder.write<DepthWeightMap>("depth_weight");
}

void DepthWarpMergeCpuStage::run(StageContext& context) {
  const FrameInfo& frame = context.get(frame_);
  const DepthMap* previous_depth = context.get(previous_depth_);
  const DepthWeightMap* previous_weight = context.get(previous_weight_);
  const FrameInfo* previous_frame = context.get(previous_frame_);
  const DepthMap& depth = context.get(depth_);
  if (previous_depth && previous_weight && previous_depth->same_shape(depth)) {
    const Pose current = frame.camera_to_world.value_or(Pose::Identity());
    const Pose previous =
        previous_frame && previous_frame->camera_to_world ? *previous_frame->camera_to_world : Pose::Identity();
    warp_depth(*previous_depth, *previous_weight, frame.intrinsics, current.inverse() * previous, options_, warped_,
               warped_weight_);
  } else {
    warped_.resize(0, 0);
    warped_weight_.resize(0, 0);
  }
  merge_depth(depth, warped_, warped_weight_, options_, context.get(filtered_), context.get(weight_));
}

}  // namespace relight
