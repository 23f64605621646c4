// normals/tum_temporal_stability: the real TUM fr1/rpy slice shipped in data/ (no ground-truth
// normals there). Temporal stability instead: for every pair of consecutive frames, each pixel's
// surface point is moved into the previous frame with the ground-truth poses, and where the raw
// depth there agrees (same surface, not occluded: within 3 cm + 2 % of z) the angle between its
// normal now and the previous frame's normal there (both in the world frame) is averaged. The
// scene is static, so every degree of change is noise. Raw stride-1 cross products, method 1
// (stride-4 cross products blended with the history, eq. 4.4-4.8) and method 2 (warped and merged
// depth, then method 1's estimator on it, as replay runs it; "method2_plain": the stride-1 cross
// products of the merged depth) run over the same frames; "ms" is method 1's median time per frame.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "bench.h"
#include "relight/capture/tum_sequence.h"
#include "relight/core/error.h"
#include "relight/core/pixel.h"
#include "relight/reconstruct/depth_warp_merge.h"
#include "relight/reconstruct/normals_from_positions.h"
#include "relight/reconstruct/normals_raw_depth.h"
#include "replay.h"

namespace {

using namespace relight;
using relight::bench::Json;

struct Frame {
  DepthMap depth;
  Pose camera_to_world;
};

struct Stability {
  double sum_deg = 0.0;
  std::size_t pixels = 0;
  [[nodiscard]] double mean() const { return pixels ? sum_deg / static_cast<double>(pixels) : 0.0; }
};

Eigen::Vector3d world_normal(const Float3& n, const Pose& pose) {
  return pose.linear() * Eigen::Vector3d(n.x, n.y, n.z);
}

/// Adds the normal change between frame `now` and the frame before it (see the file comment).
void add_change(const Frame& before, const NormalMap& normals_before, const Frame& now, const NormalMap& normals_now,
                const PinholeIntrinsics& k, Stability& out) {
  const Pose now_to_before = before.camera_to_world.inverse() * now.camera_to_world;
  for (int r = 0; r < k.height; ++r) {
    for (int c = 0; c < k.width; ++c) {
      const float z = now.depth(r, c);
      const Float3 n = normals_now(r, c);
      if (!is_valid_depth(z) || !is_valid_normal(n)) continue;
      const Eigen::Vector3d p = now_to_before * k.unproject(c, r, z);
      if (p.z() <= 0.0) continue;
      const long u = std::lround(k.fx * p.x() / p.z() + k.cx), v = std::lround(k.fy * p.y() / p.z() + k.cy);
      if (u < 0 || v < 0 || u >= k.width || v >= k.height) continue;
      const float z_before = before.depth(static_cast<int>(v), static_cast<int>(u));
      const Float3 m = normals_before(static_cast<int>(v), static_cast<int>(u));
      if (!is_valid_depth(z_before) || !is_valid_normal(m)) continue;
      if (std::abs(z_before - p.z()) > 0.03 + 0.02 * p.z()) continue;
      const double cosine = world_normal(n, now.camera_to_world).dot(world_normal(m, before.camera_to_world));
      out.sum_deg += std::acos(std::clamp(cosine, -1.0, 1.0)) * 180.0 / 3.14159265358979323846;
      ++out.pixels;
    }
  }
}

Json tum_stability(const bench::Options& options) {
  const std::filesystem::path folder = app::default_sequence();  // data/tum_fr1_rpy, or under $RELIGHT_DATA
  const capture::TumSequence sequence = capture::TumSequence::open(folder);
  const PinholeIntrinsics& k = sequence.intrinsics();
  std::vector<Frame> frames;
  for (std::size_t i = 0; i < sequence.size(); ++i) {
    RgbdFrame f = sequence.load(i);
    if (!f.info.camera_to_world) throw Error(folder.string() + ": frame " + std::to_string(i) + " has no pose");
    frames.push_back({std::move(f.depth), *f.info.camera_to_world});
  }
  if (frames.size() < 2) throw Error(folder.string() + ": needs at least two frames");

  Stability raw, method1, method2, method2_plain;
  NormalMap raw_prev, m1_prev, m2_prev, m2_plain_prev;
  PositionMap m1_positions_prev, m2_positions_prev;
  DepthMap filtered;
  reconstruct::DepthWeightMap weight;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const Frame& f = frames[i];
    PositionMap positions;
    NormalMap raw_now, m1_now, m2_now;
    reconstruct::positions_from_depth(f.depth, k, positions);
    reconstruct::normals_from_positions(positions, raw_now);

    PositionMap m1_positions;
    const reconstruct::NormalsHistory history{m1_prev, m1_positions_prev,
                                              i > 0 ? frames[i - 1].camera_to_world : Pose::Identity()};
    reconstruct::normals_raw_depth(f.depth, k, f.camera_to_world, i > 0 ? &history : nullptr, {}, m1_positions, m1_now);

    DepthMap merged;
    reconstruct::DepthWeightMap merged_weight;
    if (i > 0) {
      DepthMap warped;
      reconstruct::DepthWeightMap warped_weight;
      const Pose now_from_before = f.camera_to_world.inverse() * frames[i - 1].camera_to_world;
      reconstruct::warp_depth(filtered, weight, k, now_from_before, {}, warped, warped_weight);
      reconstruct::merge_depth(f.depth, warped, warped_weight, {}, merged, merged_weight);
    } else {
      reconstruct::merge_depth(f.depth, DepthMap(k.width, k.height), reconstruct::DepthWeightMap(k.width, k.height), {},
                               merged, merged_weight);
    }
    PositionMap m2_positions;
    NormalMap m2_plain_now;
    const reconstruct::NormalsHistory m2_history{m2_prev, m2_positions_prev,
                                                 i > 0 ? frames[i - 1].camera_to_world : Pose::Identity()};
    reconstruct::normals_raw_depth(merged, k, f.camera_to_world, i > 0 ? &m2_history : nullptr, {}, m2_positions,
                                   m2_now);
    reconstruct::normals_from_positions(m2_positions, m2_plain_now);  // φ⁻¹(merged), as normals_raw_depth wrote them

    if (i > 0) {
      add_change(frames[i - 1], raw_prev, f, raw_now, k, raw);
      add_change(frames[i - 1], m1_prev, f, m1_now, k, method1);
      add_change(frames[i - 1], m2_prev, f, m2_now, k, method2);
      add_change(frames[i - 1], m2_plain_prev, f, m2_plain_now, k, method2_plain);
    }
    raw_prev = std::move(raw_now);
    m1_prev = std::move(m1_now);
    m1_positions_prev = std::move(m1_positions);
    m2_prev = std::move(m2_now);
    m2_positions_prev = std::move(m2_positions);
    m2_plain_prev = std::move(m2_plain_now);
    filtered = std::move(merged);
    weight = std::move(merged_weight);
  }
  // Method 1's time on a real frame, with the previous frame as history.
  const Frame& last = frames.back();
  const reconstruct::NormalsHistory history{m1_prev, m1_positions_prev, last.camera_to_world};
  PositionMap scratch_positions;
  NormalMap scratch_normals;
  reconstruct::NormalsRawDepthCpu method;
  const double ms = bench::median_ms(
      [&] { method.run(last.depth, k, last.camera_to_world, &history, {}, scratch_positions, scratch_normals); },
      options.repetitions);
  const double pixels = static_cast<double>(k.width) * k.height * static_cast<double>(frames.size() - 1);
  return {{"ms", ms},
          {"frames", frames.size()},
          {"raw_change_deg", raw.mean()},
          {"method1_change_deg", method1.mean()},
          {"method2_change_deg", method2.mean()},
          {"method2_plain_change_deg", method2_plain.mean()},
          {"raw_compared", static_cast<double>(raw.pixels) / pixels},
          {"method1_compared", static_cast<double>(method1.pixels) / pixels},
          {"method2_compared", static_cast<double>(method2.pixels) / pixels}};
}

}  // namespace

RELIGHT_BENCH_CASE("normals/tum_temporal_stability", tum_stability);
