#include "relight/render/dir/ism.h"

#include <algorithm>
#include <cmath>
#include <initializer_list>

#include "relight/core/error.h"
#include "relight/core/parallel.h"
#include "relight/render/scene/phong_brdf.h"
#include "relight/render/scene/sampler.h"
#include "relight/render/dir/shadow_maps.h"

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
  triangles.reserve(scene.triangle_count(real));
  cumulative_area.reserve(scene.triangle_count(real));
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
  // The random numbers in the order they were always drawn (a point's area target, then its
  // barycentric pair); then the points are made in ascending order of their targets, each on the
  // first triangle whose cumulative area reaches its target, in one sweep over the triangles,
  // and stored at their own draw's place. A binary search and a triangle per point in draw
  // order read the mesh at random and missed the cache at nearly every step (4 of 6 ms for a
  // reconstruction of 100k triangles).
  struct Draw {
    double target;
    float a, b;
  };
  Pcg32 random(options.seed, stream);
  std::vector<Draw> draws(count);
  for (Draw& draw : draws) {
    draw.target = random.uniform() * area;
    draw.a = random.uniform();
    draw.b = random.uniform();
  }
  std::vector<std::uint32_t> ascending(count);
  for (std::size_t i = 0; i < count; ++i) ascending[i] = static_cast<std::uint32_t>(i);
  std::ranges::sort(ascending, [&](std::uint32_t l, std::uint32_t r) { return draws[l].target < draws[r].target; });
  points.resize(count);
  std::size_t first_reaching = 0;
  for (const std::uint32_t i : ascending) {
    while (first_reaching < cumulative_area.size() && cumulative_area[first_reaching] < draws[i].target)
      ++first_reaching;
    const std::size_t pick = std::min(first_reaching, triangles.size() - 1);
    const TriangleMesh& mesh = *triangles[pick].mesh;
    const auto& tri = mesh.triangles[triangles[pick].index];
    float a = draws[i].a, b = draws[i].b;
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
    points[i] = {(1.f - a - b) * p0 + a * p1 + b * p2, normal, half_size,
                 mesh.triangle_material[triangles[pick].index]};
  }
  return points;  // already in random order: every contiguous run is a uniform subset
}

float edge(const Vec2& a, const Vec2& b, const Vec2& p) {
  return (b.x() - a.x()) * (p.y() - a.y()) - (b.y() - a.y()) * (p.x() - a.x());
}

void splat(const TileProjection& projection, const IsmPoint& point, int tile, float* texels) {
  float distance = 0.f;
  const Vec3 centre_dir = projection.local(point.position, distance);
  Vec2 centre;
  if (!(distance > 1e-4f) || centre_dir.z() <= 0.f || !projection.texel(centre_dir, tile, centre)) return;
  Vec3 tp, bp;
  orthonormal_basis(point.normal, tp, bp);
  std::array<Vec2, 4> corners;
  const std::array<std::array<float, 2>, 4> signs{{{1.f, 1.f}, {-1.f, 1.f}, {-1.f, -1.f}, {1.f, -1.f}}};
  Vec2 low = centre, high = centre;
  for (std::size_t k = 0; k < 4; ++k) {
    float corner_distance = 0.f;
    const Vec3 dir = projection.local(point.position + point.half_size * (signs[k][0] * tp + signs[k][1] * bp), corner_distance);
    // A corner behind the view keeps the centre (the quad shrinks rather than blowing up); one
    // outside a perspective view keeps its coordinates (the texel range is clamped below).
    if (!(corner_distance > 1e-4f) || dir.z() <= 1e-3f) corners[k] = centre;
    else (void)projection.texel(dir, tile, corners[k]);
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
  const Vec3 plane_normal_local(point.normal.dot(projection.t), point.normal.dot(projection.b),
                                point.normal.dot(projection.n));
  const float plane_offset = (point.position - projection.origin).dot(point.normal);
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
        const float facing = projection.direction(p, tile).dot(plane_normal_local);
        const float along = std::abs(facing) > 1e-3f ? std::clamp(plane_offset / facing, near, far) : distance;
        float& texel = texels[static_cast<std::size_t>(y) * static_cast<std::size_t>(tile) + static_cast<std::size_t>(x)];
        texel = std::min(texel, std::max(along, 0.f));
      }
    }
  float& own = texels[static_cast<std::size_t>(cy) * static_cast<std::size_t>(tile) + static_cast<std::size_t>(cx)];
  own = std::min(own, distance);
}

/// Centre and radius of a sphere around the points of `pools` (radius 0 when there are none).
Eigen::Vector4f bounding_sphere(std::initializer_list<const std::vector<IsmPoint>*> pools) {
  Eigen::AlignedBox3f box;
  for (const auto* points : pools)
    for (const IsmPoint& p : *points) box.extend(p.position);
  if (box.isEmpty()) return Eigen::Vector4f::Zero();
  const Vec3 c = box.center();
  float radius = 0.f;
  for (const auto* points : pools)
    for (const IsmPoint& p : *points) radius = std::max(radius, (p.position - c).norm() + p.half_size);
  return {c.x(), c.y(), c.z(), radius * 1.01f + 1e-3f};
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
  IsmPointPools pools{sample_layer(scene, true, options, 1), sample_layer(scene, false, options, 2)};
  if (options.focus_virtual) pools.virtual_bounds = bounding_sphere({&pools.virtual_points});
  pools.scene_bounds = bounding_sphere({&pools.real, &pools.virtual_points});
  return pools;
}

TileProjection TileProjection::hemisphere(const Vpl& vpl) {
  TileProjection p{vpl.position, {}, {}, vpl.normal, 0.f};
  orthonormal_basis(p.n, p.t, p.b);
  return p;
}

TileProjection TileProjection::towards(const Vpl& vpl, const Eigen::Vector4f& sphere) {
  const Vec3 to_centre = sphere.head<3>() - vpl.position;
  const float distance = to_centre.norm(), radius = sphere.w();
  if (!(radius > 0.f) || distance <= 1.05f * radius) return hemisphere(vpl);
  TileProjection p{vpl.position, {}, {}, to_centre / distance, radius / std::sqrt(distance * distance - radius * radius)};
  orthonormal_basis(p.n, p.t, p.b);
  return p;
}

TileProjection TileProjection::real_tile(const Vpl& vpl, const IsmPointPools& points) {
  return vpl.emitter() ? towards(vpl, points.scene_bounds) : hemisphere(vpl);
}

TileProjection TileProjection::virtual_tile(const Vpl& vpl, const IsmPointPools& points) {
  const bool focused = points.virtual_bounds.w() > 0.f;
  return towards(vpl, vpl.emitter() && !focused ? points.scene_bounds : points.virtual_bounds);
}

Vec3 TileProjection::local(const Vec3& p, float& distance) const {
  const Vec3 q = p - origin;
  distance = q.norm();
  return Vec3(q.dot(t), q.dot(b), q.dot(n)) / distance;
}

bool TileProjection::texel(const Vec3& d, int tile, Vec2& coordinates) const {
  const auto size = static_cast<float>(tile);
  if (tan_half == 0.f) {
    coordinates = paraboloid_texel(d, tile);
    return true;
  }
  if (d.z() <= 0.f) return false;
  const float scale = 1.f / (d.z() * tan_half);
  coordinates = {(d.x() * scale * 0.5f + 0.5f) * size, (d.y() * scale * 0.5f + 0.5f) * size};
  return coordinates.x() >= 0.f && coordinates.y() >= 0.f && coordinates.x() < size && coordinates.y() < size;
}

Vec3 TileProjection::direction(const Vec2& coordinates, int tile) const {
  if (tan_half == 0.f) return paraboloid_direction(coordinates, tile);
  const auto size = static_cast<float>(tile);
  return Vec3((coordinates.x() / size * 2.f - 1.f) * tan_half, (coordinates.y() / size * 2.f - 1.f) * tan_half, 1.f)
      .normalized();
}

float TileProjection::texel_angle(int tile) const {
  return tan_half == 0.f ? 4.f / static_cast<float>(tile) : 2.f * tan_half / static_cast<float>(tile);
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
        const bool real = t < static_cast<int>(vpls.size());
        const TileProjection projection =
            real ? TileProjection::real_tile(vpls[vpl], points) : TileProjection::virtual_tile(vpls[vpl], points);
        for (int i = 0; i < options.points_per_vpl; ++i)
          splat(projection, pool[ism_point_index(vpl, static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(pool.size()))], tile,
                texels);
      }
      fill_holes(
          texels, tile,
          vpls[vpl].emitter() ? std::min(options.pull_push_levels, kEmitterPullPushLevels) : options.pull_push_levels);
    }
  }, 4);
  return atlas;
}

IsmLookup::IsmLookup(std::span<const float> atlas, const IsmOptions& options, std::span<const Vpl> vpls,
                     const IsmPointPools& points)
    : atlas_(atlas),
      tile_(options.tile),
      layer_stride_(vpls.size() * static_cast<std::size_t>(options.tile) * static_cast<std::size_t>(options.tile)) {
  if (atlas.size() < 2 * layer_stride_) throw Error("the ISM atlas is smaller than its VPLs need");
  real_.reserve(vpls.size());
  virtual_.reserve(vpls.size());
  for (const Vpl& vpl : vpls) {
    real_.push_back(TileProjection::real_tile(vpl, points));
    virtual_.push_back(TileProjection::virtual_tile(vpl, points));
    emitter_.push_back(vpl.emitter());
  }
}

float IsmLookup::visible(const TileProjection& projection, std::size_t tile_offset, const Vec3& from_origin,
                         float distance, float constant_bias) const {
  // TileProjection::local() with the offset and its length given.
  const Vec3 dir =
      Vec3(from_origin.dot(projection.t), from_origin.dot(projection.b), from_origin.dot(projection.n)) / distance;
  Vec2 texel;
  if (!(distance > 0.f) || !projection.texel(dir, tile_, texel)) return 1.f;
  const int x = std::clamp(static_cast<int>(std::floor(texel.x())), 0, tile_ - 1);
  const int y = std::clamp(static_cast<int>(std::floor(texel.y())), 0, tile_ - 1);
  const std::size_t i = tile_offset + static_cast<std::size_t>(y) * static_cast<std::size_t>(tile_) + static_cast<std::size_t>(x);
  // Two texels' worth of angle, plus the constant (kIsmBias, kEmitterVirtualIsmBias).
  const float reach = distance - (constant_bias + distance * 2.f * projection.texel_angle(tile_));
  return reach <= atlas_[i] ? 1.f : 0.f;
}

IsmLookup::Visibility IsmLookup::operator()(std::uint32_t index, const Vec3& point) const {
  // Both tiles of a VPL share its position as their origin (TileProjection::hemisphere, towards).
  const Vec3 from_vpl = point - real_[index].origin;
  return (*this)(index, from_vpl, from_vpl.norm());
}

IsmLookup::Visibility IsmLookup::operator()(std::uint32_t index, const Vec3& from_vpl, float distance) const {
  const std::size_t offset = static_cast<std::size_t>(index) * static_cast<std::size_t>(tile_) * static_cast<std::size_t>(tile_);
  const float real = visible(real_[index], offset, from_vpl, distance, kIsmBias);
  if (real == 0.f) return {0.f, 0.f};
  return {real, visible(virtual_[index], layer_stride_ + offset, from_vpl, distance,
                        emitter_[index] ? kEmitterVirtualIsmBias : kIsmBias)};
}

}  // namespace relight::render
