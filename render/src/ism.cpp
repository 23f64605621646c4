#include "relight/render/ism.h"

#include <algorithm>
#include <cmath>

#include "relight/core/error.h"
#include "relight/core/parallel.h"
#include "relight/render/phong_brdf.h"
#include "relight/render/sampler.h"
#include "relight/render/shadow_maps.h"

namespace relight::render {
namespace {

using Vec3 = Eigen::Vector3f;
using Vec2 = Eigen::Vector2f;

void validate(const IsmOptions& options) {
  if (options.tile < 8 || options.tile > 512) throw Error("the ISM tile must have 8 to 512 texels per side");
  if (options.points_per_vpl < 1 || options.pool_factor < 1) throw Error("the ISM point counts must be positive");
  if (static_cast<long>(options.points_per_vpl) * options.pool_factor > 65536)
    throw Error("the ISM point pool holds at most 65536 points per layer (points_per_vpl * pool_factor)");
  if (options.pull_push_levels < 0 || (options.tile >> options.pull_push_levels) < 2)
    throw Error("too many ISM pull-push levels for the tile size");
}

std::vector<IsmPoint> sample_layer(const MrScene& scene, bool real, const IsmOptions& options, std::uint64_t stream) {
  struct Triangle {
    const TriangleMesh* mesh;
    std::size_t index;
  };
  std::vector<Triangle> triangles;
  std::vector<double> cumulative_area;
  double area = 0.0;
  for (const TriangleMesh& mesh : scene.meshes) {
    if (mesh.real != real) continue;
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
      const auto& tri = mesh.triangles[t];
      area += 0.5 * (mesh.positions[tri[1]] - mesh.positions[tri[0]]).cross(mesh.positions[tri[2]] - mesh.positions[tri[0]]).norm();
      triangles.push_back({&mesh, t});
      cumulative_area.push_back(area);
    }
  }
  std::vector<IsmPoint> points;
  if (triangles.empty() || !(area > 0.0)) return points;
  const auto count = static_cast<std::size_t>(options.pool_factor) * static_cast<std::size_t>(options.points_per_vpl);
  const auto half_size = static_cast<float>(0.5 * std::sqrt(area / options.points_per_vpl));
  Pcg32 random(options.seed, stream);
  points.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    const double target = random.uniform() * area;
    const auto pick = std::min(static_cast<std::size_t>(std::lower_bound(cumulative_area.begin(), cumulative_area.end(), target) -
                                                        cumulative_area.begin()),
                               triangles.size() - 1);
    const TriangleMesh& mesh = *triangles[pick].mesh;
    const auto& tri = mesh.triangles[triangles[pick].index];
    float a = random.uniform(), b = random.uniform();
    if (a + b > 1.f) {
      a = 1.f - a;
      b = 1.f - b;
    }
    const Vec3& p0 = mesh.positions[tri[0]];
    const Vec3& p1 = mesh.positions[tri[1]];
    const Vec3& p2 = mesh.positions[tri[2]];
    Vec3 normal = (p1 - p0).cross(p2 - p0).normalized();
    if (!mesh.normals.empty()) {
      const Vec3 n = ((1.f - a - b) * mesh.normals[tri[0]] + a * mesh.normals[tri[1]] + b * mesh.normals[tri[2]]);
      if (n.squaredNorm() > 0.f) normal = n.normalized();
    }
    points.push_back({(1.f - a - b) * p0 + a * p1 + b * p2, normal, half_size});
  }
  return points;  // already in random order: every contiguous run is a uniform subset
}

struct VplFrame {
  Vec3 origin, t, b, n;

  explicit VplFrame(const Vpl& vpl) : origin(vpl.position), n(vpl.normal) { orthonormal_basis(n, t, b); }
  /// Unit direction towards `p` in the frame, and the distance.
  [[nodiscard]] Vec3 local(const Vec3& p, float& distance) const {
    const Vec3 q = p - origin;
    distance = q.norm();
    return Vec3(q.dot(t), q.dot(b), q.dot(n)) / distance;
  }
};

float edge(const Vec2& a, const Vec2& b, const Vec2& p) {
  return (b.x() - a.x()) * (p.y() - a.y()) - (b.y() - a.y()) * (p.x() - a.x());
}

void splat(const VplFrame& frame, const IsmPoint& point, int tile, float* texels) {
  float distance = 0.f;
  const Vec3 centre_dir = frame.local(point.position, distance);
  if (!(distance > 1e-4f) || centre_dir.z() <= 0.f) return;
  const Vec2 centre = paraboloid_texel(centre_dir, tile);
  Vec3 tp, bp;
  orthonormal_basis(point.normal, tp, bp);
  std::array<Vec2, 4> corners;
  const std::array<std::array<float, 2>, 4> signs{{{1.f, 1.f}, {-1.f, 1.f}, {-1.f, -1.f}, {1.f, -1.f}}};
  Vec2 low = centre, high = centre;
  for (std::size_t k = 0; k < 4; ++k) {
    float corner_distance = 0.f;
    const Vec3 c = point.position + point.half_size * (signs[k][0] * tp + signs[k][1] * bp);
    const Vec3 dir = frame.local(c, corner_distance);
    corners[k] = corner_distance > 1e-4f ? paraboloid_texel(dir, tile) : centre;
    low = low.cwiseMin(corners[k]);
    high = high.cwiseMax(corners[k]);
  }
  const int cx = std::clamp(static_cast<int>(std::floor(centre.x())), 0, tile - 1);
  const int cy = std::clamp(static_cast<int>(std::floor(centre.y())), 0, tile - 1);
  const int x0 = std::max({0, static_cast<int>(std::floor(low.x())), cx - kMaxSplat / 2});
  const int y0 = std::max({0, static_cast<int>(std::floor(low.y())), cy - kMaxSplat / 2});
  const int x1 = std::min({tile - 1, static_cast<int>(std::floor(high.x())), x0 + kMaxSplat - 1});
  const int y1 = std::min({tile - 1, static_cast<int>(std::floor(high.y())), y0 + kMaxSplat - 1});
  // The splat is a piece of the point's tangent plane: each texel stores the distance along its
  // own direction to that plane (within the splat's depth range), so that a plane seen at a
  // grazing angle does not shadow itself.
  const Vec3 to_point = point.position - frame.origin;
  const Vec3 plane_normal_local(point.normal.dot(frame.t), point.normal.dot(frame.b), point.normal.dot(frame.n));
  const float plane_offset = to_point.dot(point.normal);
  const float near = distance - 2.f * point.half_size, far = distance + 2.f * point.half_size;
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) {
      const Vec2 p(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f);
      bool positive = true, negative = true;
      for (std::size_t k = 0; k < 4; ++k) {
        const float e = edge(corners[k], corners[(k + 1) % 4], p);
        positive = positive && e >= 0.f;
        negative = negative && e <= 0.f;
      }
      if (positive || negative) {
        const float facing = paraboloid_direction(p, tile).dot(plane_normal_local);
        const float along = std::abs(facing) > 1e-3f ? std::clamp(plane_offset / facing, near, far) : distance;
        float& texel = texels[static_cast<std::size_t>(y) * static_cast<std::size_t>(tile) + static_cast<std::size_t>(x)];
        texel = std::min(texel, std::max(along, 0.f));
      }
    }
  float& own = texels[static_cast<std::size_t>(cy) * static_cast<std::size_t>(tile) + static_cast<std::size_t>(cx)];
  own = std::min(own, distance);
}

/// Pull-push over one tile (see the header).
void fill_holes(float* texels, int tile, int levels) {
  std::vector<std::vector<float>> pyramid(static_cast<std::size_t>(levels) + 1);
  pyramid[0].assign(texels, texels + static_cast<std::size_t>(tile) * static_cast<std::size_t>(tile));
  for (int l = 1; l <= levels; ++l) {
    const int size = tile >> l;
    const std::vector<float>& fine = pyramid[static_cast<std::size_t>(l - 1)];
    std::vector<float>& coarse = pyramid[static_cast<std::size_t>(l)];
    coarse.assign(static_cast<std::size_t>(size) * static_cast<std::size_t>(size), kShadowEmpty);
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) {
        float sum = 0.f;
        int valid = 0;
        for (int k = 0; k < 4; ++k) {
          const float v = fine[static_cast<std::size_t>(2 * y + k / 2) * static_cast<std::size_t>(2 * size) +
                               static_cast<std::size_t>(2 * x + k % 2)];
          if (v < kShadowEmpty) {
            sum += v;
            ++valid;
          }
        }
        if (valid >= 2) coarse[static_cast<std::size_t>(y) * static_cast<std::size_t>(size) + static_cast<std::size_t>(x)] =
            sum / static_cast<float>(valid);
      }
  }
  for (int l = levels - 1; l >= 0; --l) {
    const int size = tile >> l;
    std::vector<float>& fine = pyramid[static_cast<std::size_t>(l)];
    const std::vector<float>& coarse = pyramid[static_cast<std::size_t>(l + 1)];
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) {
        float& v = fine[static_cast<std::size_t>(y) * static_cast<std::size_t>(size) + static_cast<std::size_t>(x)];
        if (v >= kShadowEmpty) v = coarse[static_cast<std::size_t>(y / 2) * static_cast<std::size_t>(size / 2) + static_cast<std::size_t>(x / 2)];
      }
  }
  std::copy(pyramid[0].begin(), pyramid[0].end(), texels);
}

}  // namespace

IsmPointPools sample_ism_points(const MrScene& scene, const IsmOptions& options) {
  validate(options);
  return {sample_layer(scene, true, options, 1), sample_layer(scene, false, options, 2)};
}

Vec3 paraboloid_direction(const Vec2& texel, int tile) {
  const auto size = static_cast<float>(tile);
  const float u = texel.x() / size * 2.f - 1.f, v = texel.y() / size * 2.f - 1.f;
  const float r2 = u * u + v * v;
  const float scale = 2.f / (1.f + r2);
  return {u * scale, v * scale, (1.f - r2) / (1.f + r2)};
}

Vec2 paraboloid_texel(const Vec3& d, int tile) {
  const float scale = 1.f / (1.f + std::max(d.z(), 0.f));
  const auto size = static_cast<float>(tile);
  return {(d.x() * scale * 0.5f + 0.5f) * size, (d.y() * scale * 0.5f + 0.5f) * size};
}

std::vector<float> ism_atlas_cpu(const IsmPointPools& points, std::span<const Vpl> vpls, const IsmOptions& options) {
  validate(options);
  const int tile = options.tile;
  const std::size_t texels_per_tile = static_cast<std::size_t>(tile) * static_cast<std::size_t>(tile);
  std::vector<float> atlas(2 * vpls.size() * texels_per_tile, kShadowEmpty);
  const int tiles = static_cast<int>(2 * vpls.size());
  parallel_rows(tiles, 0, [&](int begin, int end) {
    for (int t = begin; t < end; ++t) {
      const auto vpl = static_cast<std::uint32_t>(t) % static_cast<std::uint32_t>(vpls.size());
      const std::vector<IsmPoint>& pool = t < static_cast<int>(vpls.size()) ? points.real : points.virtual_points;
      float* texels = atlas.data() + static_cast<std::size_t>(t) * texels_per_tile;
      if (!pool.empty()) {
        const VplFrame frame(vpls[vpl]);
        for (int i = 0; i < options.points_per_vpl; ++i)
          splat(frame, pool[ism_point_index(vpl, static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(pool.size()))], tile,
                texels);
      }
      fill_holes(texels, tile, options.pull_push_levels);
    }
  }, 4);
  return atlas;
}

IsmLookup::IsmLookup(std::span<const float> atlas, const IsmOptions& options, std::span<const Vpl> vpls)
    : atlas_(atlas),
      tile_(options.tile),
      layer_stride_(vpls.size() * static_cast<std::size_t>(options.tile) * static_cast<std::size_t>(options.tile)) {
  if (atlas.size() < 2 * layer_stride_) throw Error("the ISM atlas is smaller than its VPLs need");
  frames_.reserve(vpls.size());
  for (const Vpl& vpl : vpls) {
    Frame f{vpl.position, {}, {}, vpl.normal};
    orthonormal_basis(f.n, f.t, f.b);
    frames_.push_back(f);
  }
}

IsmLookup::Visibility IsmLookup::operator()(std::uint32_t index, const Vec3& point) const {
  const Frame& f = frames_[index];
  const Vec3 q = point - f.origin;
  const float distance = q.norm();
  if (!(distance > 0.f)) return {};
  const Vec2 texel = paraboloid_texel(Vec3(q.dot(f.t), q.dot(f.b), q.dot(f.n)) / distance, tile_);
  const int x = std::clamp(static_cast<int>(std::floor(texel.x())), 0, tile_ - 1);
  const int y = std::clamp(static_cast<int>(std::floor(texel.y())), 0, tile_ - 1);
  const std::size_t i = (index * static_cast<std::size_t>(tile_) + static_cast<std::size_t>(y)) * static_cast<std::size_t>(tile_) +
                        static_cast<std::size_t>(x);
  // Two texels' worth of angle (a paraboloid texel spans about 4 / tile radians at the pole).
  const float reach = distance - (0.02f + distance * 8.f / static_cast<float>(tile_));
  return {reach <= atlas_[i] ? 1.f : 0.f, reach <= atlas_[layer_stride_ + i] ? 1.f : 0.f};
}

}  // namespace relight::render
