// CPU implementation of method 1 (definition in normals_raw_depth.h).
#include <algorithm>
#include <cmath>
#include <vector>

#include "relight/core/error.h"
#include "relight/core/parallel.h"
#include "relight/reconstruct/normals_from_positions.h"
#include "relight/reconstruct/normals_raw_depth.h"

namespace relight {

namespace {

Float3 normalized_or_zero(const Float3& v) {
  const float len = length(v);
  return len > 0.f ? (1.f / len) * v : Float3{};
}

float pow128(float x) {
  for (int i = 0; i < 7; ++i) x *= x;
  return x;
}

using NormalLevel = NormalsPyramidLevel;

// Pass 1 at half resolution: texel (r, c) summarises full-resolution pixel (2r, 2c).
NormalLevel average_and_curvature(const NormalMap& previous, int threads) {
  const int width = (previous.width() + 1) / 2;
  const int height = (previous.height() + 1) / 2;
  NormalLevel level{Image<Float3>(width, height), Image<float>(width, height)};
  const auto at = [&](int r, int c) -> Float3 {
    return previous.in_bounds(r, c) ? previous(r, c) : Float3{};
  };
  parallel_rows(height, threads, [&](int begin, int end) {
    for (int hr = begin; hr < end; ++hr) {
      for (int hc = 0; hc < width; ++hc) {
        const int r = 2 * hr, c = 2 * hc;
        const Float3 up = at(r - 1, c), down = at(r + 1, c), left = at(r, c - 1), right = at(r, c + 1);
        level.normal(hr, hc) = normalized_or_zero(at(r, c) + up + down + left + right);  // missing ones are 0
        const bool horizontal = is_valid_normal(left) && is_valid_normal(right);
        const bool vertical = is_valid_normal(up) && is_valid_normal(down);
        const float curv = horizontal && vertical ? std::min(dot(left, right), dot(up, down)) : 0.f;
        level.curvature(hr, hc) = pow128(std::clamp(curv, 0.f, 1.f));
      }
    }
  });
  return level;
}

NormalLevel downsample(const NormalLevel& fine) {
  const int width = (fine.normal.width() + 1) / 2;
  const int height = (fine.normal.height() + 1) / 2;
  NormalLevel coarse{Image<Float3>(width, height), Image<float>(width, height)};
  for (int r = 0; r < height; ++r) {
    for (int c = 0; c < width; ++c) {
      Float3 sum;
      float curvature = 0.f;
      int count = 0;
      for (int dr = 0; dr < 2; ++dr) {
        for (int dc = 0; dc < 2; ++dc) {
          if (!fine.normal.in_bounds(2 * r + dr, 2 * c + dc)) continue;
          const Float3& n = fine.normal(2 * r + dr, 2 * c + dc);
          if (!is_valid_normal(n)) continue;
          sum += n;
          curvature += fine.curvature(2 * r + dr, 2 * c + dc);
          ++count;
        }
      }
      coarse.normal(r, c) = normalized_or_zero(sum);
      coarse.curvature(r, c) = count > 0 ? curvature / static_cast<float>(count) : 0.f;
    }
  }
  return coarse;
}

std::vector<NormalLevel> build_pyramid(const NormalMap& previous, int levels, int threads) {
  std::vector<NormalLevel> pyramid;
  pyramid.push_back(average_and_curvature(previous, threads));
  while (static_cast<int>(pyramid.size()) < levels && pyramid.back().normal.width() > 1 &&
         pyramid.back().normal.height() > 1) {
    pyramid.push_back(downsample(pyramid.back()));
  }
  return pyramid;
}

// Row-major float 3x4 rigid transform, for the inner loops.
struct Rigid {
  float m[3][4];
  explicit Rigid(const Pose& pose) {
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c) m[r][c] = static_cast<float>(pose.matrix()(r, c));
    }
  }
  [[nodiscard]] Float3 point(const Float3& p) const {
    return {m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3],
            m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3],
            m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3]};
  }
  [[nodiscard]] Float3 direction(const Float3& d) const {
    return {m[0][0] * d.x + m[0][1] * d.y + m[0][2] * d.z, m[1][0] * d.x + m[1][1] * d.y + m[1][2] * d.z,
            m[2][0] * d.x + m[2][1] * d.y + m[2][2] * d.z};
  }
};

// Pass 2's temporal blend for one pixel with a fresh normal `fresh` at camera-frame position p.
Float3 blend_with_history(const Float3& fresh, const Float3& p, const NormalsHistory& previous,
                          const std::vector<NormalLevel>& pyramid, const Rigid& prev_from_current,
                          const Rigid& current_from_prev, const PinholeIntrinsics& intrinsics,
                          const NormalsRawDepthOptions& options) {
  const Float3 q = prev_from_current.point(p);
  if (!(q.z > 0.f)) return fresh;
  const float u = static_cast<float>(intrinsics.fx) * q.x / q.z + static_cast<float>(intrinsics.cx);
  const float v = static_cast<float>(intrinsics.fy) * q.y / q.z + static_cast<float>(intrinsics.cy);
  const int col = static_cast<int>(std::lround(u));
  const int row = static_cast<int>(std::lround(v));
  if (!previous.positions.in_bounds(row, col)) return fresh;
  const float previous_z = previous.positions(row, col).z;
  if (!(previous_z > 0.f) || std::fabs(previous_z - q.z) > options.disocclusion_m) return fresh;

  const int max_level = static_cast<int>(pyramid.size()) - 1;
  const float curvature = pyramid[0].curvature(row / 2, col / 2);
  const int level = std::clamp(static_cast<int>(std::lround(curvature * static_cast<float>(max_level))), 0, max_level);
  Float3 history = pyramid[level].normal(row >> (level + 1), col >> (level + 1));
  if (!is_valid_normal(history)) history = pyramid[0].normal(row / 2, col / 2);
  if (!is_valid_normal(history)) return fresh;
  history = current_from_prev.direction(history);

  const float c_n = std::fabs(dot(history, fresh));
  const float c = options.blend_base * c_n + (1.f - c_n);
  const Float3 blended = normalized_or_zero(c * history + (1.f - c) * fresh);
  return is_valid_normal(blended) ? blended : fresh;
}

// Holes: pixels with a position but no normal take the mean of their valid 4-neighbours.
void fill_holes(const PositionMap& positions, NormalMap& normals) {
  std::vector<std::pair<std::size_t, Float3>> fills;
  const int width = normals.width();
  for (int r = 0; r < normals.height(); ++r) {
    for (int c = 0; c < width; ++c) {
      if (!(positions(r, c).z > 0.f) || is_valid_normal(normals(r, c))) continue;
      Float3 sum;
      if (r > 0) sum += normals(r - 1, c);
      if (r + 1 < normals.height()) sum += normals(r + 1, c);
      if (c > 0) sum += normals(r, c - 1);
      if (c + 1 < width) sum += normals(r, c + 1);
      const Float3 n = normalized_or_zero(sum);
      if (is_valid_normal(n)) fills.emplace_back(static_cast<std::size_t>(r) * static_cast<std::size_t>(width) + static_cast<std::size_t>(c), n);
    }
  }
  for (const auto& [index, n] : fills) normals.pixels()[index] = n;
}

}  // namespace

std::vector<NormalsPyramidLevel> normals_history_pyramid(const NormalMap& previous, int levels, int threads) {
  return build_pyramid(previous, std::max(1, levels), threads);
}

void normals_raw_depth(const DepthMap& depth, const PinholeIntrinsics& intrinsics, const Pose& camera_to_world,
                       const NormalsHistory* previous, const NormalsRawDepthOptions& options,
                       PositionMap& positions, NormalMap& normals) {
  positions_from_depth(depth, intrinsics, positions, options.threads);
  normals_from_positions(positions, normals,
                         {.stride = options.stride, .max_jump_rel = options.max_jump_rel, .threads = options.threads});
  normals_raw_depth_blend(intrinsics, camera_to_world, previous, options, positions, normals);
}

void normals_raw_depth_blend(const PinholeIntrinsics& intrinsics, const Pose& camera_to_world,
                             const NormalsHistory* previous, const NormalsRawDepthOptions& options,
                             const PositionMap& positions, NormalMap& normals) {
  if (!normals.same_shape(positions)) throw LogicError("normals_raw_depth_blend: normals and positions differ in shape");
  const bool usable_history =
      previous && previous->normals.same_shape(positions) && previous->positions.same_shape(positions);
  if (usable_history) {
    const std::vector<NormalLevel> pyramid = build_pyramid(previous->normals, std::max(1, options.mip_levels),
                                                           options.threads);
    const Pose prev_from_current_pose = previous->camera_to_world.inverse() * camera_to_world;
    const Rigid prev_from_current(prev_from_current_pose);
    const Rigid current_from_prev(prev_from_current_pose.inverse());
    parallel_rows(positions.height(), options.threads, [&](int begin, int end) {
      for (int r = begin; r < end; ++r) {
        for (int c = 0; c < positions.width(); ++c) {
          Float3& n = normals(r, c);
          if (!is_valid_normal(n)) continue;
          n = blend_with_history(n, positions(r, c), *previous, pyramid, prev_from_current, current_from_prev,
                                 intrinsics, options);
        }
      }
    });
  }
  fill_holes(positions, normals);
}

void NormalsRawDepthStageBase::declare(StageBuilder& builder) {
  depth_ = builder.read<DepthMap>("depth");
  frame_ = builder.read<FrameInfo>("frame");
  previous_normals_ = builder.read_previous<NormalMap>("normals");
  previous_positions_ = builder.read_previous<PositionMap>("positions");
  previous_frame_ = builder.read_previous<FrameInfo>("frame");
  positions_ = builder.write<PositionMap>("positions");
  normals_ = builder.write<NormalMap>("normals");
}

void NormalsRawDepthStageBase::run(StageContext& context) {
  const FrameInfo& frame = context.get(frame_);
  const Pose camera_to_world = frame.camera_to_world.value_or(Pose::Identity());
  const NormalMap* previous_normals = context.get(previous_normals_);
  const PositionMap* previous_positions = context.get(previous_positions_);
  const FrameInfo* previous_frame = context.get(previous_frame_);
  std::optional<NormalsHistory> history;
  if (previous_normals && previous_positions) {
    const Pose previous_pose =
        previous_frame && previous_frame->camera_to_world ? *previous_frame->camera_to_world : Pose::Identity();
    history.emplace(NormalsHistory{*previous_normals, *previous_positions, previous_pose});
  }
  estimate(context, context.get(depth_), frame.intrinsics, camera_to_world, history ? &*history : nullptr,
           context.get(positions_), context.get(normals_));
}

void NormalsRawDepthCpuStage::estimate(StageContext&, const DepthMap& depth, const PinholeIntrinsics& intrinsics,
                                       const Pose& camera_to_world, const NormalsHistory* previous,
                                       PositionMap& positions, NormalMap& normals) {
  normals_raw_depth(depth, intrinsics, camera_to_world, previous, options(), positions, normals);
}

}  // namespace relight
