#include "relight/render/reference/dir_exact.h"

#include <algorithm>
#include <limits>
#include <span>

#include "relight/core/error.h"
#include "relight/core/parallel.h"
#include "scene/surface_shading.h"

namespace relight::render {
namespace {

using namespace detail;

struct PixelResult {
  Vec3 real_virtual = Vec3::Zero();
  Vec3 real = Vec3::Zero();
  bool virtual_pixel = false;
};

class DirShader {
 public:
  DirShader(const MrScene& scene, const RayTracer& tracer, const std::vector<Vpl>& vpls, const DirOptions& options)
      : scene_(scene),
        tracer_(tracer),
        bounce_vpls_(std::span(vpls).first(vpls.size() - emitter_count(vpls))),
        emitters_(std::span(vpls).subspan(bounce_vpls_.size())),
        options_(options) {}

  [[nodiscard]] PixelResult shade(const Vec3& origin, const Vec3& direction) const {
    PixelResult out;
    const std::optional<SurfaceHit> real = tracer_.intersect(Layer::Real, origin, direction);
    const std::optional<SurfaceHit> virtual_hit =
        tracer_.intersect(Layer::Virtual, origin, direction, real ? real->t : std::numeric_limits<float>::infinity());
    const std::optional<SurfaceHit>& hit = virtual_hit ? virtual_hit : real;
    if (!hit) {
      out.real_virtual = out.real = scene_.environment.radiance;
      return out;
    }
    out.virtual_pixel = !hit->real;
    const Vertex v = make_vertex(*hit, direction, scene_);
    const float real_pixel = hit->real ? 1.f : 0.f;  // r(p)
    out.real_virtual += v.emission;
    out.real += real_pixel * v.emission;
    if (options_.direct) add_direct(v, real_pixel, out);
    if (options_.indirect) add_indirect(v, real_pixel, out);
    return out;
  }

 private:
  struct Visibility {
    bool real = false;           ///< V_r
    bool real_virtual = false;   ///< min(V_r, V_v)
  };

  [[nodiscard]] Visibility visibility(const Vertex& v, const Vec3& wi, float reach) const {
    const Vec3 from = offset_origin(v, wi);
    Visibility out;
    out.real = !tracer_.occluded(Layer::Real, from, wi, reach);
    out.real_virtual = out.real && !tracer_.occluded(Layer::Virtual, from, wi, reach);
    return out;
  }

  void add_direct(const Vertex& v, float real_pixel, PixelResult& out) const {
    for (const MrLight& light : scene_.lights) {
      if (light.through_vpl) continue;  // its emitter VPL lights the point (vpl.h)
      const std::optional<LightSample> sample = sample_light(light, v.point);
      if (!sample) continue;
      const Vec3 contribution = direct_light(v, *sample);
      if (contribution.isZero()) continue;
      const Visibility seen = visibility(v, sample->wi, sample->distance * (1.f - 1e-4f));
      if (seen.real_virtual) out.real_virtual += contribution;
      if (seen.real && light.real) out.real += real_pixel * contribution;
    }
    for (const Vpl& emitter : emitters_) add_emitter(v, real_pixel, emitter, out);
  }

  void add_indirect(const Vertex& v, float real_pixel, PixelResult& out) const {
    const float min_distance2 = options_.min_distance * options_.min_distance;
    for (const Vpl& vpl : bounce_vpls_) {
      if (!vpl.in_real_virtual && (!vpl.in_real || real_pixel == 0.f)) continue;
      const Vec3 to_vpl = vpl.position - v.point;
      const float distance2 = to_vpl.squaredNorm();
      if (!(distance2 > 0.f)) continue;
      const float distance = std::sqrt(distance2);
      const Vec3 wi = to_vpl / distance;
      const float cos_x = wi.dot(v.shading_normal);
      const float cos_y = -wi.dot(vpl.normal);
      if (cos_x <= 0.f || cos_y <= 0.f || wi.dot(v.geometric_normal) <= 0.f) continue;
      const Vec3 f_y = phong_brdf(vpl_phong(scene_, vpl), vpl.normal, vpl.incident, -wi);
      const Vec3 f_x = phong_brdf(v.brdf, v.shading_normal, wi, v.wo);
      const Vec3 contribution =
          vpl.flux.cwiseProduct(f_y).cwiseProduct(f_x) * (cos_x * cos_y / std::max(distance2, min_distance2));
      if (contribution.isZero()) continue;
      // Stop short of the VPL's own surface.
      const float reach = distance - 1e-3f * (1.f + vpl.position.cwiseAbs().maxCoeff());
      const Visibility seen = visibility(v, wi, reach);
      if (seen.real_virtual && vpl.in_real_virtual) out.real_virtual += contribution;
      if (seen.real && vpl.in_real) out.real += real_pixel * contribution;
    }
  }

  /// An emitter VPL: the directional light it stands for, with exact visibility.
  void add_emitter(const Vertex& v, float real_pixel, const Vpl& vpl, PixelResult& out) const {
    const float infinity = std::numeric_limits<float>::infinity();
    const Vec3 contribution = direct_light(v, LightSample{vpl.incident, infinity, vpl.flux});
    if (contribution.isZero()) return;
    const Visibility seen = visibility(v, vpl.incident, infinity);
    if (seen.real_virtual && vpl.in_real_virtual) out.real_virtual += contribution;
    if (seen.real && vpl.in_real) out.real += real_pixel * contribution;
  }

  const MrScene& scene_;
  const RayTracer& tracer_;
  std::span<const Vpl> bounce_vpls_;
  std::span<const Vpl> emitters_;  ///< the last VPLs (vpl.h): direct light, in add_direct
  const DirOptions& options_;
};

}  // namespace

DifferentialImages shade_instant_radiosity(const MrScene& scene, const RayTracer& tracer, const MrCamera& camera,
                                           const std::vector<Vpl>& vpls, const DirOptions& options) {
  if (!(options.min_distance > 0.f)) throw Error("the VPL clamp distance must be positive");
  const PinholeIntrinsics& k = camera.intrinsics;
  if (k.width <= 0 || k.height <= 0) throw Error("the render size must be positive");
  DifferentialImages out;
  out.real_virtual = RadianceImage(k.width, k.height);
  out.real = RadianceImage(k.width, k.height);
  out.virtual_coverage = CoverageImage(k.width, k.height);
  out.samples_per_pixel = 1;
  const DirShader shader(scene, tracer, vpls, options);
  const Vec3 origin = camera.camera_to_world.translation().cast<float>();
  parallel_rows(k.height, options.threads, [&](int begin, int end) {
    for (int row = begin; row < end; ++row)
      for (int col = 0; col < k.width; ++col) {
        const Eigen::Vector3d d = camera.camera_to_world.linear() * k.ray(col, row).normalized();
        const PixelResult p = shader.shade(origin, d.cast<float>().normalized());
        out.real_virtual(row, col) = {p.real_virtual.x(), p.real_virtual.y(), p.real_virtual.z()};
        out.real(row, col) = {p.real.x(), p.real.y(), p.real.z()};
        out.virtual_coverage(row, col) = p.virtual_pixel ? 1.f : 0.f;
      }
  }, 2);
  return out;
}

}  // namespace relight::render
