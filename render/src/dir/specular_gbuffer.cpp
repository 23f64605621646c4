#include "relight/render/dir/specular_gbuffer.h"

#include <algorithm>

#include "relight/core/parallel.h"
#include "relight/render/scene/luminance.h"
#include "relight/render/scene/specular_bsdf.h"
#include "scene/surface_shading.h"

namespace relight::render {
namespace {

using Vec3 = Eigen::Vector3f;

const SpecularMaterial& specular_of(const MrScene& scene, const SurfaceHit& hit) {
  return scene.materials.at(hit.material).specular;
}

/// Just off the surface on the side `direction` leaves towards (no self-hit).
Vec3 leave(const SurfaceHit& hit, const Vec3& direction) {
  const float scale = 1e-4f * (1.f + hit.point.cwiseAbs().maxCoeff());
  return hit.point + (direction.dot(hit.geometric_normal) >= 0.f ? scale : -scale) * hit.geometric_normal;
}

struct BranchEnd {
  std::optional<SurfaceHit> surface;  ///< the diffuse surface; none: the branch left the scene
  Vec3 weight = Vec3::Zero();
  Vec3 eye = Vec3::Zero();
  Vec3 direction = Vec3::Zero();
};

/// Follows one branch from the specular surface `at`, starting along `first` (a lobe of its
/// material), to the first diffuse surface or out of the scene.
BranchEnd follow(const RayTracer& tracer, const SurfaceHit& at, const SpecularSample& first, int max_vertices,
                 bool real_world) {
  const MrScene& scene = tracer.scene();
  BranchEnd end;
  end.weight = first.weight;
  SurfaceHit from = at;
  Vec3 direction = first.wi;
  // The dielectric the ray travels through (Beer-Lambert), if any: entered by a refraction and
  // left by the next one (nested dielectrics are not modelled, specular_material.h).
  const SpecularMaterial* medium =
      first.transmitted && at.interpolated_normal.dot(direction) < 0.f ? &specular_of(scene, at) : nullptr;
  std::uint32_t rays = 0;
  for (int vertex = 1;; ++vertex) {
    const Vec3 origin = leave(from, direction);
    std::optional<SurfaceHit> hit = detail::nearest_hit(tracer, origin, direction, !real_world, rays);
    // From surface to surface, not from the offset origin.
    if (medium && hit) end.weight = end.weight.cwiseProduct(beer_lambert(*medium, (hit->point - from.point).norm()));
    end.eye = origin;
    end.direction = direction;
    if (!hit) return end;  // into the environment
    const SpecularMaterial& material = specular_of(scene, *hit);
    if (!material.specular()) {
      end.surface = std::move(hit);
      return end;
    }
    if (vertex >= max_vertices) {
      end.weight.setZero();
      return end;
    }
    const SpecularLobes lobes = specular_lobes(material, hit->interpolated_normal, -direction, Transport::Radiance);
    const bool refract = lobes.refracted &&
                         (!lobes.reflected || luminance(lobes.refracted->weight) >= luminance(lobes.reflected->weight));
    const SpecularSample& next = refract ? *lobes.refracted : *lobes.reflected;
    end.weight = end.weight.cwiseProduct(next.weight);
    if (next.transmitted) medium = medium ? nullptr : &material;
    direction = next.wi;
    from = *hit;
  }
}

}  // namespace

bool has_specular_surfaces(const MrScene& scene) {
  for (const TriangleMesh& mesh : scene.meshes)
    for (const std::uint32_t m : mesh.triangle_material)
      if (m < scene.materials.size() && scene.materials[m].specular.specular()) return true;
  return false;
}

SpecularGBuffers specular_gbuffers_cpu(const RayTracer& tracer, const MrCamera& camera, const GBuffer& primary,
                                       const SpecularTraceOptions& options) {
  const MrScene& scene = tracer.scene();
  const int width = primary.position.width(), height = primary.position.height();
  const bool textured = has_textures(scene);
  const auto branch = [&] {
    return SpecularBranch{empty_gbuffer(width, height, textured), RadianceImage(width, height),
                          PositionMap(width, height)};
  };
  SpecularGBuffers out{branch(), branch(), Mask(width, height)};
  const Vec3 centre = camera.camera_to_world.translation().cast<float>();
  const auto store = [](SpecularBranch& b, int row, int col, const BranchEnd& end) {
    b.weight(row, col) = {end.weight.x(), end.weight.y(), end.weight.z()};
    b.eye(row, col) = {end.eye.x(), end.eye.y(), end.eye.z()};
    // Mip level 0 in reflections: the footprint of a pixel after a curved mirror is not tracked.
    if (end.surface) store_hit(b.gbuffer, row, col, *end.surface, end.direction, 0.f);
  };
  std::vector<int> counts(static_cast<std::size_t>(height), 0);
  parallel_rows(
      height, options.threads,
      [&](int begin, int end) {
        for (int row = begin; row < end; ++row)
          for (int col = 0; col < width; ++col) {
            const std::uint16_t label = primary.material(row, col);
            if (label == 0 || !scene.materials.at(label - 1u).specular.specular()) continue;
            if (options.real_world && primary.virtual_surface(row, col)) continue;
            // The camera ray again, for the hit's own winding (the G-buffer's normal faces the camera).
            const Float3& p = primary.position(row, col);
            const Vec3 d = (Vec3(p.x, p.y, p.z) - centre).normalized();
            std::uint32_t rays = 0;
            const std::optional<SurfaceHit> hit = detail::nearest_hit(tracer, centre, d, !options.real_world, rays);
            if (!hit || !specular_of(scene, *hit).specular()) continue;
            out.specular(row, col) = 1;
            ++counts[static_cast<std::size_t>(row)];
            const SpecularLobes lobes =
                specular_lobes(specular_of(scene, *hit), hit->interpolated_normal, -d, Transport::Radiance);
            if (lobes.reflected)
              store(out.reflected, row, col,
                    follow(tracer, *hit, *lobes.reflected, options.max_vertices, options.real_world));
            if (lobes.refracted)
              store(out.refracted, row, col,
                    follow(tracer, *hit, *lobes.refracted, options.max_vertices, options.real_world));
          }
      },
      4);
  for (const int c : counts) out.pixels += c;
  return out;
}

}  // namespace relight::render
