#include "relight/render/dir/shadow_maps.h"

#include <algorithm>
#include <cmath>

#include "relight/core/error.h"
#include "relight/core/parallel.h"

namespace relight::render {
namespace {

using Vec3 = Eigen::Vector3f;

constexpr float kNear = 0.01f;
constexpr float kFar = 100.f;
constexpr float kMaxSpotHalfAngle = 1.309f;  // 75 degrees: wider spots use the six cube faces
/// A focused view's half-angle is this much wider than the virtual objects' bounding sphere, and
/// a light must be this many radii from its centre to get one.
constexpr float kFocusMargin = 1.02f;

/// World-to-view rotation rows (right, down, forward): relight's camera convention.
Eigen::Matrix3f view_rotation(const Vec3& forward) {
  const Vec3 helper = std::abs(forward.z()) < 0.9f ? Vec3::UnitZ() : Vec3::UnitX();
  const Vec3 right = helper.cross(forward).normalized();
  const Vec3 down = forward.cross(right);
  Eigen::Matrix3f rows;
  rows.row(0) = right;
  rows.row(1) = down;
  rows.row(2) = forward;
  return rows;
}

ShadowView perspective_view(const Vec3& eye, const Vec3& forward, float half_angle, int tile) {
  const float t = std::tan(half_angle);
  Eigen::Matrix4f view = Eigen::Matrix4f::Identity();
  const Eigen::Matrix3f rotation = view_rotation(forward.normalized());
  view.topLeftCorner<3, 3>() = rotation;
  view.topRightCorner<3, 1>() = -rotation * eye;
  Eigen::Matrix4f projection = Eigen::Matrix4f::Zero();
  projection(0, 0) = 1.f / t;
  projection(1, 1) = 1.f / t;
  projection(2, 2) = kFar / (kFar - kNear);
  projection(2, 3) = -kFar * kNear / (kFar - kNear);
  projection(3, 2) = 1.f;
  return {projection * view, Eigen::Vector4f(eye.x(), eye.y(), eye.z(), 1.f), 2.f * t / static_cast<float>(tile)};
}

ShadowView orthographic_view(const Vec3& towards_light, const Vec3& centre, float radius, int tile) {
  const Vec3 forward = -towards_light.normalized();
  const Eigen::Matrix3f rotation = view_rotation(forward);
  Eigen::Matrix4f m = Eigen::Matrix4f::Zero();
  m.block<1, 3>(0, 0) = rotation.row(0) / radius;
  m.block<1, 3>(1, 0) = rotation.row(1) / radius;
  m.block<1, 3>(2, 0) = rotation.row(2) / (2.f * radius);
  m(0, 3) = -rotation.row(0).dot(centre) / radius;
  m(1, 3) = -rotation.row(1).dot(centre) / radius;
  m(2, 3) = 0.5f - rotation.row(2).dot(centre) / (2.f * radius);
  m(3, 3) = 1.f;
  const Vec3 u = towards_light.normalized();
  return {m, Eigen::Vector4f(u.x(), u.y(), u.z(), 0.f), 2.f * radius / static_cast<float>(tile)};
}

int cube_face(const Vec3& from_light) {
  int axis = 0;
  from_light.cwiseAbs().maxCoeff(&axis);
  return 2 * axis + (from_light[axis] < 0.f ? 1 : 0);
}

}  // namespace

ShadowLayout plan_shadow_views(const MrScene& scene, int tile) {
  if (tile < 16) throw Error("the shadow-map tile must be at least 16 texels");
  ShadowLayout layout;
  layout.tile = tile;
  const BoundingSphere bounds = bounding_sphere(scene);
  const Vec3 centre = bounds.radius > 0.f ? bounds.centre : Vec3::Zero();
  const float radius = bounds.radius > 0.f ? bounds.radius : 1.f;
  const BoundingSphere virtual_bounds = bounding_sphere(scene, SceneMeshes::Virtual);
  for (const MrLight& light : scene.lights) {
    const auto first = static_cast<std::uint32_t>(layout.views.size());
    const float spot_half_angle = std::acos(std::clamp(light.cos_outer, -1.f, 1.f)) * 1.02f;
    if (light.through_vpl) {
      // Shadowed by its emitter VPL's imperfect shadow map (vpl.h): no views.
    } else if (light.kind == LightKind::Directional) {
      layout.views.push_back(orthographic_view(light.direction, centre, radius, tile));
      if (virtual_bounds.radius > 0.f) {
        layout.virtual_views.push_back(
            orthographic_view(light.direction, virtual_bounds.centre, virtual_bounds.radius, tile));
      }
    } else {
      const bool spot = light.kind == LightKind::Spot && spot_half_angle <= kMaxSpotHalfAngle;
      if (spot) {
        layout.views.push_back(perspective_view(light.position, light.direction, spot_half_angle, tile));
      } else {
        for (int face = 0; face < 6; ++face) {
          Vec3 forward = Vec3::Zero();
          forward[face / 2] = face % 2 == 0 ? 1.f : -1.f;
          layout.views.push_back(perspective_view(light.position, forward, static_cast<float>(M_PI / 4), tile));
        }
      }
      // The virtual layer's view: the cone around the virtual objects, every view of the light
      // alike (the lookup picks a cube face by direction; each face then holds the same view).
      const Vec3 to_virtual = virtual_bounds.centre - light.position;
      const float distance = to_virtual.norm();
      if (virtual_bounds.radius > 0.f && distance > kFocusMargin * virtual_bounds.radius) {
        const float half_angle = std::asin(virtual_bounds.radius / distance) * kFocusMargin;
        if (half_angle < (spot ? spot_half_angle : kMaxSpotHalfAngle)) {
          const ShadowView focused = perspective_view(light.position, to_virtual / distance, half_angle, tile);
          layout.virtual_views.insert(layout.virtual_views.end(), spot ? 1 : 6, focused);
        }
      }
    }
    // Views of a light without a focused virtual view (and of any light in a scene without
    // virtual objects) are the same for both layers.
    const auto shared = layout.views.begin() + static_cast<std::ptrdiff_t>(layout.virtual_views.size());
    layout.virtual_views.insert(layout.virtual_views.end(), shared, layout.views.end());
    layout.light_views.push_back({first, static_cast<std::uint32_t>(layout.views.size()) - first});
  }
  layout.columns = std::clamp(static_cast<int>(layout.views.size()), 1, 8);
  return layout;
}

float light_depth(const ShadowView& view, const Vec3& point) {
  const Vec3 eye = view.eye.head<3>();
  return view.eye.w() > 0.5f ? (point - eye).norm() : -point.dot(eye);
}

std::vector<float> shadow_atlas_cpu(const RayTracer& tracer, const ShadowLayout& layout, int threads) {
  const int width = layout.atlas_width(), height = layout.atlas_height();
  std::vector<float> atlas(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), kShadowEmpty);
  const int tile = layout.tile;
  const int tile_rows = static_cast<int>(layout.views.size()) * 2 * tile;
  parallel_rows(tile_rows, threads, [&](int begin, int end) {
    for (int row = begin; row < end; ++row) {
      const int view_index = row / (2 * tile), layer = (row / tile) % 2, y = row % tile;
      const ShadowView& view = layout.view(static_cast<std::size_t>(view_index), layer);
      const Eigen::Matrix4f clip_to_world = view.world_to_clip.inverse();
      const auto [ox, oy] = layout.tile_origin(view_index, layer);
      for (int x = 0; x < tile; ++x) {
        const float nx = (static_cast<float>(x) + 0.5f) / static_cast<float>(tile) * 2.f - 1.f;
        const float ny = (static_cast<float>(y) + 0.5f) / static_cast<float>(tile) * 2.f - 1.f;
        const Eigen::Vector4f near = clip_to_world * Eigen::Vector4f(nx, ny, 0.f, 1.f);
        const Eigen::Vector4f far = clip_to_world * Eigen::Vector4f(nx, ny, 1.f, 1.f);
        const Vec3 from = near.head<3>() / near.w(), to = far.head<3>() / far.w();
        const float length = (to - from).norm();
        const auto hit = tracer.intersect(layer == 0 ? Layer::Real : Layer::Virtual, from, (to - from) / length, length);
        if (hit) atlas[static_cast<std::size_t>(oy + y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(ox + x)] =
            light_depth(view, hit->point);
      }
    }
  }, 8);
  return atlas;
}

float shadow_visibility(const ShadowLayout& layout, std::span<const float> atlas, std::uint32_t light, int layer,
                        const Vec3& point, const Vec3& normal, float surface_tolerance) {
  return ShadowLookup(layout, atlas)(light, layer, point, normal, surface_tolerance);
}

ShadowLookup::ShadowLookup(const ShadowLayout& layout, std::span<const float> atlas)
    : tile_(layout.tile), atlas_width_(static_cast<std::size_t>(layout.atlas_width())) {
  if (atlas.size() < atlas_width_ * static_cast<std::size_t>(layout.atlas_height()))
    throw Error("shadow lookup: the atlas is smaller than its layout");
  for (int layer = 0; layer < 2; ++layer) {
    auto& views = views_[static_cast<std::size_t>(layer)];
    for (std::size_t v = 0; v < layout.views.size(); ++v) {
      const auto [ox, oy] = layout.tile_origin(static_cast<int>(v), layer);
      views.push_back({&layout.view(v, layer),
                       atlas.data() + static_cast<std::size_t>(oy) * atlas_width_ + static_cast<std::size_t>(ox)});
    }
    for (const auto& [first, count] : layout.light_views) {
      Light light{first, count};
      if (count > 0) {
        const ShadowView& any = layout.view(first, layer);
        light.positional = any.eye.w() > 0.5f;
        light.eye = any.eye.head<3>();
        light.unit_towards = light.eye.normalized();
      }
      lights_[static_cast<std::size_t>(layer)].push_back(light);
    }
  }
}

float ShadowLookup::operator()(std::uint32_t light_index, int layer, const Vec3& point, const Vec3& normal,
                               float surface_tolerance) const {
  const auto& lights = lights_[layer == 0 ? 0 : 1];
  if (light_index >= lights.size()) return 1.f;
  const Light& light = lights[light_index];
  if (light.count == 0) return 1.f;
  const Vec3 towards_light = light.positional ? Vec3(light.eye - point) : light.eye;
  const std::uint32_t index =
      light.count == 6 ? light.first + static_cast<std::uint32_t>(cube_face(point - light.eye)) : light.first;
  const View& tile = views_[layer == 0 ? 0 : 1][index];
  const ShadowView& view = *tile.view;
  // Against shadow acne: the receiver moves half a texel (measured at the receiver) off its
  // surface, and the depth test allows one texel. Larger offsets lift receivers next to a
  // contact (a virtual object standing on a real table) out of its shadow (bench
  // dir/vs_reference: 1.5 texels doubled the direct-light error of DeltaL).
  const float texel = light.positional ? view.texel_size * towards_light.norm() : view.texel_size;
  const Vec3 facing = normal.dot(towards_light) < 0.f ? Vec3(-normal) : normal;
  const Vec3 unit_towards = light.positional ? Vec3(towards_light.normalized()) : light.unit_towards;
  const float cos_incidence = std::max(std::abs(normal.dot(unit_towards)), 0.2f);
  const float tolerance = texel + surface_tolerance / cos_incidence;
  const Vec3 receiver = point + 0.5f * texel * facing;
  const Eigen::Vector4f clip = view.world_to_clip * receiver.homogeneous();
  if (clip.w() <= 0.f) return 1.f;
  const float nx = clip.x() / clip.w(), ny = clip.y() / clip.w();
  if (std::abs(nx) > 1.f || std::abs(ny) > 1.f) return 1.f;
  const int tx = std::clamp(static_cast<int>(std::floor((nx * 0.5f + 0.5f) * static_cast<float>(tile_))), 0, tile_ - 1);
  const int ty = std::clamp(static_cast<int>(std::floor((ny * 0.5f + 0.5f) * static_cast<float>(tile_))), 0, tile_ - 1);
  const float stored = tile.texels[static_cast<std::size_t>(ty) * atlas_width_ + static_cast<std::size_t>(tx)];
  const float depth = light_depth(view, receiver);
  return depth <= stored + tolerance ? 1.f : 0.f;
}

}  // namespace relight::render
