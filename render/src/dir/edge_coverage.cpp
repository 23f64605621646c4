#include "relight/render/dir/edge_coverage.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>

#include "relight/core/parallel.h"

namespace relight::render {

namespace {

constexpr float kDepthAgreement = 0.05f;  // relative: neighbouring centres on one surface

bool seen_virtual(const GBuffer& g, int row, int col) {
  return g.distance(row, col) != 0.f && g.virtual_surface(row, col) != 0;
}

/// Distance from the camera centre to the real surface at pixel centre (row, col); infinity
/// where the reconstruction has none.
float real_distance(const PositionMap& positions, int row, int col) {
  const Float3& p = positions(row, col);
  if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z) || !(p.z > 0.f))
    return std::numeric_limits<float>::infinity();
  return length(p);
}

/// The real surface's distance at sub-pixel (u, v) (pixel centres at integers).
float real_distance_at(const PositionMap& positions, float u, float v) {
  const int width = positions.width(), height = positions.height();
  const float x = std::clamp(u, 0.f, float(width - 1)), y = std::clamp(v, 0.f, float(height - 1));
  const int x0 = std::min(static_cast<int>(x), width - 2 < 0 ? 0 : width - 2);
  const int y0 = std::min(static_cast<int>(y), height - 2 < 0 ? 0 : height - 2);
  const int x1 = std::min(x0 + 1, width - 1), y1 = std::min(y0 + 1, height - 1);
  const float fx = x - float(x0), fy = y - float(y0);
  const float d[4] = {real_distance(positions, y0, x0), real_distance(positions, y0, x1),
                      real_distance(positions, y1, x0), real_distance(positions, y1, x1)};
  const float lo = std::min({d[0], d[1], d[2], d[3]}), hi = std::max({d[0], d[1], d[2], d[3]});
  if (std::isfinite(hi) && hi <= lo * (1.f + kDepthAgreement))
    return (1.f - fy) * ((1.f - fx) * d[0] + fx * d[1]) + fy * ((1.f - fx) * d[2] + fx * d[3]);
  const int nx = fx < 0.5f ? x0 : x1, ny = fy < 0.5f ? y0 : y1;  // a depth edge: the nearest centre
  return real_distance(positions, ny, nx);
}

}  // namespace

Mask outline_pixels(const GBuffer& gbuffer) {
  // A pixel's 3x3 window holds both kinds exactly when a neighbour is of the other kind: walk the
  // virtual pixels (few) and mark each with its non-virtual neighbours.
  const int width = gbuffer.distance.width(), height = gbuffer.distance.height();
  Mask out(width, height);
  for (int row = 0; row < height; ++row) {
    for (int col = 0; col < width; ++col) {
      if (!seen_virtual(gbuffer, row, col)) continue;
      for (int i = -1; i <= 1; ++i)
        for (int j = -1; j <= 1; ++j) {
          const int r = row + i, c = col + j;
          if (r < 0 || c < 0 || r >= height || c >= width || seen_virtual(gbuffer, r, c)) continue;
          out(r, c) = 1;
          out(row, col) = 1;
        }
    }
  }
  return out;
}

int refine_edge_coverage(CoverageImage& coverage, const GBuffer& gbuffer, const PositionMap& real_positions,
                         const RayTracer& virtual_tracer, const MrCamera& camera, const EdgeCoverageOptions& options) {
  const Mask outline = outline_pixels(gbuffer);
  const int width = coverage.width(), height = coverage.height();
  const int n = std::max(1, options.samples);
  const PinholeIntrinsics& k = camera.intrinsics;
  const Eigen::Matrix3d rotation = camera.camera_to_world.linear();
  const Eigen::Vector3f origin = camera.camera_to_world.translation().cast<float>();
  std::atomic<int> count{0};
  parallel_for_each_row(height, options.threads, [&](int row) {
    int here = 0;
    for (int col = 0; col < width; ++col) {
      if (!outline(row, col)) continue;
      ++here;
      int hits = 0;
      for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
          const float u = float(col) + (float(j) + 0.5f) / float(n) - 0.5f;
          const float v = float(row) + (float(i) + 0.5f) / float(n) - 0.5f;
          const Eigen::Vector3d ray = k.ray(u, v);
          const float to_real = real_distance_at(real_positions, u, v);
          // The position map's distance is along the ray too (|p| of the camera-frame point).
          const Eigen::Vector3f direction = (rotation * ray.normalized()).cast<float>();
          if (virtual_tracer.intersect(Layer::Virtual, origin, direction, to_real)) ++hits;
        }
      }
      coverage(row, col) = float(hits) / float(n * n);
    }
    count += here;
  });
  return count.load();
}

MrScene virtual_part(const MrScene& scene) {
  MrScene out;
  out.materials = scene.materials;
  out.environment = scene.environment;
  for (const TriangleMesh& mesh : scene.meshes)
    if (!mesh.real) out.meshes.push_back(mesh);
  return out;
}

}  // namespace relight::render
