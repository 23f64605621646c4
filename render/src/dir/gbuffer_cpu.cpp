#include <algorithm>
#include <cmath>

#include "relight/core/parallel.h"
#include "relight/render/dir/gbuffer.h"
#include "relight/render/scene/normal_map.h"

namespace relight::render {
namespace {

/// How far the hit's texture coordinates move to where the ray `next` meets the hit's plane (a
/// ray differential: the neighbouring pixel's ray against the same triangle's plane).
float texcoord_step(const SurfaceHit& hit, const Eigen::Vector3f& origin, const Eigen::Vector3f& next) {
  const float facing = next.dot(hit.geometric_normal);
  if (!(std::abs(facing) > 1e-6f)) return 0.f;
  const float t = (hit.point - origin).dot(hit.geometric_normal) / facing;
  if (!(t > 0.f)) return 0.f;
  return (hit.texcoord_gradient * (origin + t * next - hit.point)).norm();
}

}  // namespace

bool has_textures(const MrScene& scene) {
  return std::any_of(scene.materials.begin(), scene.materials.end(), [](const PhongMaterial& m) {
    return m.base_color != nullptr || m.emission_texture != nullptr || m.metallic_roughness_texture != nullptr ||
           m.normal_texture != nullptr;
  });
}

RadianceImage texture_factors(const GBuffer& gbuffer, const MrScene& scene, MaterialTexture which) {
  const auto texture_of = [which](const PhongMaterial& m) {
    switch (which) {
      case MaterialTexture::BaseColor: return m.base_color.get();
      case MaterialTexture::Emission: return m.emission_texture.get();
      case MaterialTexture::MetallicRoughness: return m.metallic_roughness_texture.get();
      case MaterialTexture::Normal: break;
    }
    return m.normal_texture.get();
  };
  if (gbuffer.texcoord.empty() || std::none_of(scene.materials.begin(), scene.materials.end(),
                                               [&](const PhongMaterial& m) { return texture_of(m); }))
    return {};
  RadianceImage out(gbuffer.texcoord.width(), gbuffer.texcoord.height());
  for (std::size_t i = 0; i < out.size(); ++i) {
    out.pixels()[i] = {1.f, 1.f, 1.f};
    const std::uint16_t label = gbuffer.material.pixels()[i];
    if (label == 0) continue;
    const Texture* texture = texture_of(scene.materials.at(label - 1u));
    if (!texture) continue;
    const Float3& t = gbuffer.texcoord.pixels()[i];
    // A footprint of zero marks a pixel without coordinates (the coordinates themselves may be 0).
    const Eigen::Vector2f uv(t.x, t.y);
    const Eigen::Vector3f c = texture_at(texture, t.z > 0.f ? &uv : nullptr, texture->level_of_detail(t.z));
    out.pixels()[i] = {c.x(), c.y(), c.z()};
  }
  return out;
}

NormalMap shading_normals(const GBuffer& gbuffer, const MrScene& scene) {
  const RadianceImage texels = texture_factors(gbuffer, scene, MaterialTexture::Normal);
  if (texels.empty() || gbuffer.tangent.empty()) return {};
  NormalMap out = gbuffer.normal;
  for (std::size_t i = 0; i < out.size(); ++i) {
    const std::uint16_t label = gbuffer.material.pixels()[i];
    if (label == 0) continue;
    const PhongMaterial& material = scene.materials.at(label - 1u);
    if (!material.normal_texture) continue;
    const Float3& n = gbuffer.normal.pixels()[i];
    const Eigen::Vector3f normal(n.x, n.y, n.z);
    const std::optional<TangentFrame> frame = decode_tangent(gbuffer.tangent.pixels()[i], normal);
    if (!frame) continue;
    const Float3& t = texels.pixels()[i];
    const Eigen::Vector3f bent = mapped_normal(normal, *frame, Eigen::Vector3f(t.x, t.y, t.z), material.normal_scale);
    out.pixels()[i] = {bent.x(), bent.y(), bent.z()};
  }
  return out;
}

GBuffer empty_gbuffer(int width, int height, bool textured) {
  GBuffer out{PositionMap(width, height), NormalMap(width, height), LabelImage(width, height), Mask(width, height),
              DepthMap(width, height)};
  if (textured) {
    out.texcoord = Image<Float3>(width, height);
    out.tangent = Image<float>(width, height);
  }
  return out;
}

void store_hit(GBuffer& g, int row, int col, const SurfaceHit& hit, const Eigen::Vector3f& direction,
               float texcoord_footprint) {
  const bool back = hit.interpolated_normal.dot(direction) > 0.f;
  const Eigen::Vector3f n = back ? Eigen::Vector3f(-hit.interpolated_normal) : hit.interpolated_normal;
  g.position(row, col) = {hit.point.x(), hit.point.y(), hit.point.z()};
  g.normal(row, col) = {n.x(), n.y(), n.z()};
  g.material(row, col) = static_cast<std::uint16_t>(hit.material + 1);
  g.virtual_surface(row, col) = hit.real ? 0 : 1;
  g.distance(row, col) = hit.t;
  if (g.texcoord.empty() || !hit.has_texcoord) return;
  // At least a little above zero: zero marks "no coordinates" (texture_factors).
  g.texcoord(row, col) = {hit.texcoord.x(), hit.texcoord.y(), std::max(texcoord_footprint, 1e-12f)};
  std::optional<TangentFrame> frame = tangent_frame(hit.texcoord_gradient, hit.interpolated_normal);
  if (frame && back) frame = flipped(*frame);
  g.tangent(row, col) = encode_tangent(frame, n);
}

GBuffer gbuffer_cpu(const RayTracer& tracer, const MrCamera& camera, int threads) {
  const PinholeIntrinsics& k = camera.intrinsics;
  const bool textured = has_textures(tracer.scene());
  GBuffer out = empty_gbuffer(k.width, k.height, textured);
  const Eigen::Vector3f origin = camera.camera_to_world.translation().cast<float>();
  const auto ray = [&](int col, int row) {
    return (camera.camera_to_world.linear() * k.ray(col, row).normalized()).cast<float>().eval();
  };
  parallel_rows(k.height, threads, [&](int begin, int end) {
    for (int row = begin; row < end; ++row)
      for (int col = 0; col < k.width; ++col) {
        const Eigen::Vector3f d = ray(col, row);
        const auto real = tracer.intersect(Layer::Real, origin, d);
        const auto virtual_hit =
            tracer.intersect(Layer::Virtual, origin, d, real ? real->t : std::numeric_limits<float>::infinity());
        const auto& hit = virtual_hit ? virtual_hit : real;
        if (!hit) continue;
        const float footprint = textured && hit->has_texcoord ? std::max(texcoord_step(*hit, origin, ray(col + 1, row)),
                                                                         texcoord_step(*hit, origin, ray(col, row + 1)))
                                                              : 0.f;
        store_hit(out, row, col, *hit, d, footprint);
      }
  }, 4);
  return out;
}

}  // namespace relight::render
