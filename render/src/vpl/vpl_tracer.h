#pragma once
// The two-world light tracer of VPL generation (vpl.h; Knecht 2010 §3.3): follows a light path
// segment through the real and the virtual layer and records the VPL(s) it ends in - one lit with
// the virtual objects present, one on the real surface behind a virtual hit lit only without
// them - and continues the path by sampling the VPL's BRDF, by ray tracing or, for
// BounceMethod::PointCone, by a cone search over surface points for all segments of a bounce.
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "relight/render/dir/ism.h"  // sample_ism_points: the point pools the cone search reads
#include "relight/render/reference/ray_tracer.h"
#include "relight/render/scene/sampler.h"
#include "relight/render/scene/specular_bsdf.h"
#include "relight/render/vpl/cone_search.h"
#include "relight/render/vpl/cone_search_vk.h"
#include "relight/render/vpl/vpl.h"
#include "scene/surface_shading.h"
#include "vpl/light_sampling.h"

namespace relight::render::vpl_detail {

/// A continued path segment waiting for the point-cone search of its bounce.
struct PendingSegment {
  Vec3 origin, normal, direction, flux;
  bool in_real_virtual = true, in_real = true;
  int bounce = 2;
  std::uint32_t light = 0, parent = Vpl::kNoParent;
  Pcg32 rng;
};

/// BounceMethod::PointCone's search (cone_search.h) over each layer's points, for all segments
/// of one bounce at once: on the GPU when there is one, else on the CPU.
class ConeSearch {
 public:
  ConeSearch(const MrScene& scene, const VplOptions& options, ConeSearchVk* gpu)
      : points_(sample_ism_points(scene, {.points_per_vpl = options.cone_points, .pool_factor = 1, .seed = options.seed})),
        half_angle_deg_(options.cone_half_angle_deg),
        gpu_(gpu) {}

  struct Hits {
    std::optional<SurfaceHit> real, virtual_hit;  ///< the virtual one only when nearer
  };

  [[nodiscard]] std::vector<Hits> resolve(const std::vector<PendingSegment>& segments) const {
    std::vector<ConeQuery> queries;
    queries.reserve(segments.size());
    for (const PendingSegment& s : segments) queries.push_back({s.origin, s.normal, s.direction});
    const std::vector<ConeHit> real = search(points_.real, queries);
    for (std::size_t i = 0; i < queries.size(); ++i) queries[i].max_t = real[i].t;
    const std::vector<ConeHit> virtual_hits = search(points_.virtual_points, queries);
    std::vector<Hits> hits(segments.size());
    for (std::size_t i = 0; i < segments.size(); ++i) {
      hits[i].real = surface_hit(points_.real, segments[i], real[i], true);
      hits[i].virtual_hit = surface_hit(points_.virtual_points, segments[i], virtual_hits[i], false);
    }
    return hits;
  }

 private:
  [[nodiscard]] std::vector<ConeHit> search(const std::vector<IsmPoint>& points,
                                            const std::vector<ConeQuery>& queries) const {
    if (!gpu_ || points.empty()) return cone_search_cpu(points, queries, half_angle_deg_);
    gpu_->set_points(points);
    return gpu_->search(queries, half_angle_deg_);
  }

  static std::optional<SurfaceHit> surface_hit(const std::vector<IsmPoint>& points, const PendingSegment& segment,
                                               const ConeHit& hit, bool real) {
    if (hit.point == ConeHit::kNone) return std::nullopt;
    const IsmPoint& point = points[hit.point];
    SurfaceHit out;
    out.t = hit.t;
    out.point = segment.origin + hit.t * segment.direction;
    out.geometric_normal = out.interpolated_normal = out.shading_normal = point.normal;
    out.material = point.material;
    out.real = real;
    return out;
  }

  IsmPointPools points_;
  float half_angle_deg_;
  ConeSearchVk* gpu_;
};

class VplTracer {
 public:
  VplTracer(const MrScene& scene, const RayTracer& tracer, const VplOptions& options, std::vector<Vpl>& out,
            ConeSearchVk* gpu)
      : scene_(scene), tracer_(tracer), options_(options), out_(out) {
    if (options.bounces > 1 && options.bounce_method == BounceMethod::PointCone) cone_.emplace(scene, options, gpu);
  }

  /// The primary light whose paths the following emit() calls follow.
  void set_light(std::size_t light) { light_ = static_cast<std::uint32_t>(light); }

  /// Follows one light path segment and records the VPL(s) it ends in.
  void emit(const Vec3& origin, const Vec3& direction, const Vec3& flux, bool in_real_virtual, bool in_real, int bounce,
            Pcg32& rng, std::uint32_t parent = Vpl::kNoParent) {
    if (flux.maxCoeff() <= 0.f || (!in_real_virtual && !in_real)) return;
    const std::optional<SurfaceHit> real = tracer_.intersect(Layer::Real, origin, direction);
    const std::optional<SurfaceHit> virtual_hit =
        tracer_.intersect(Layer::Virtual, origin, direction, real ? real->t : std::numeric_limits<float>::infinity());
    record(real, virtual_hit, direction, flux, in_real_virtual, in_real, bounce, rng, parent);
  }

  /// BounceMethod::PointCone: resolves the waiting segments bounce by bounce until none is left.
  void finish() {
    while (!pending_.empty()) {
      const std::vector<PendingSegment> segments = std::exchange(pending_, {});
      const std::vector<ConeSearch::Hits> hits = cone_->resolve(segments);
      for (std::size_t i = 0; i < segments.size(); ++i) {
        PendingSegment s = segments[i];
        light_ = s.light;
        record(hits[i].real, hits[i].virtual_hit, s.direction, s.flux, s.in_real_virtual, s.in_real, s.bounce, s.rng,
               s.parent);
      }
    }
  }

  /// The VPL(s) a path segment ends in, given what it reached in each layer (the virtual hit
  /// only when nearer than the real one).
  void record(const std::optional<SurfaceHit>& real, const std::optional<SurfaceHit>& virtual_hit, const Vec3& direction,
              const Vec3& flux, bool in_real_virtual, bool in_real, int bounce, Pcg32& rng, std::uint32_t parent) {
    if (virtual_hit) {
      // The two worlds part here: the virtual surface is lit with the virtual objects present,
      // the real surface behind it only without them.
      add(*virtual_hit, direction, flux, in_real_virtual, false, bounce, rng, parent);
      if (real) add(*real, direction, flux, false, in_real, bounce, rng, parent);
    } else if (real) {
      add(*real, direction, flux, in_real_virtual, in_real, bounce, rng, parent);
    }
  }

  /// Records a VPL at `hit`, lit along `direction`, and continues its path.
  void add(const SurfaceHit& hit, const Vec3& direction, const Vec3& flux, bool in_real_virtual, bool in_real, int bounce,
           Pcg32& rng, std::uint32_t parent = Vpl::kNoParent) {
    if (!in_real_virtual && !in_real) return;
    if (scene_.materials[hit.material].specular.specular()) {
      follow_specular(hit, direction, flux, in_real_virtual, in_real, bounce, rng, parent);
      return;
    }
    Vpl vpl;
    vpl.position = hit.point;
    vpl.incident = -direction;
    const Vec3 geometric = hit.geometric_normal.dot(vpl.incident) < 0.f ? Vec3(-hit.geometric_normal) : hit.geometric_normal;
    vpl.normal = hit.shading_normal.dot(geometric) < 0.f ? Vec3(-hit.shading_normal) : hit.shading_normal;
    if (vpl.normal.dot(vpl.incident) <= 0.f) vpl.normal = geometric;
    vpl.geometric_normal = geometric;
    vpl.flux = flux;
    vpl.material = hit.material;
    vpl.kd_texture = base_color_at(scene_, hit);
    vpl.metallic_roughness = metallic_roughness_at(scene_, hit);
    vpl.on_real_surface = hit.real;
    vpl.in_real_virtual = in_real_virtual;
    vpl.in_real = in_real;
    vpl.bounce = bounce;
    vpl.light = light_;
    vpl.parent = parent;
    const auto index = static_cast<std::uint32_t>(out_.size());
    out_.push_back(vpl);
    // The multiple-bounce light source continues this path next frame, not now (vpl.h).
    if (bounce >= options_.bounces || options_.bounce_method == BounceMethod::PreviousFrame) return;
    // Continue the light path by sampling the VPL's BRDF (reciprocity: wo = where light came from).
    const float u1 = rng.uniform(), u2 = rng.uniform();
    const auto sample = sample_phong(vpl_phong(scene_, vpl), vpl.normal, vpl.incident, u1, u2);
    if (!sample || sample->wi.dot(geometric) <= 0.f) return;
    const Vec3 next_flux = flux.cwiseProduct(sample->weight);
    if (cone_) {
      if (next_flux.maxCoeff() > 0.f)
        pending_.push_back({vpl.position, geometric, sample->wi, next_flux, vpl.in_real_virtual, vpl.in_real, bounce + 1,
                            light_, index, rng});
      return;
    }
    const float offset = 1e-4f * (1.f + vpl.position.cwiseAbs().maxCoeff());
    emit(vpl.position + offset * geometric, sample->wi, next_flux, vpl.in_real_virtual, vpl.in_real, bounce + 1, rng,
         index);
  }

  /// Specular vertices one light path may pass before it is dropped (glass: entry, exit and
  /// internal reflections).
  static constexpr int kMaxSpecularVertices = 8;

  /// Caustic VPLs (Knecht et al., TVCG 2013 §4.2.2): a path that meets a mirror or glass leaves
  /// no VPL there (a delta BRDF cannot light other surfaces as a point light) but goes on in the
  /// mirrored or refracted direction to the diffuse surface it reaches, which gets the VPL - light
  /// focused by the object (LSDE, LSSDE) that lights its surroundings in turn. Where the paper
  /// picks reflection or refraction 50/50 by a Halton number and doubles the flux, the choice here
  /// is in proportion to the Fresnel term (sample_specular, importance transport: the flux is not
  /// scaled), so each branch carries its physical share; Beer-Lambert absorbs inside glass.
  void follow_specular(SurfaceHit hit, Vec3 direction, Vec3 flux, bool in_real_virtual, bool in_real, int bounce,
                       Pcg32& rng, std::uint32_t parent) {
    const SpecularMaterial* medium = nullptr;
    for (int vertex = 0; vertex < kMaxSpecularVertices; ++vertex) {
      const SpecularMaterial& material = scene_.materials[hit.material].specular;
      const std::optional<SpecularSample> sample =
          sample_specular(material, hit.interpolated_normal, -direction, rng.uniform(), Transport::Importance);
      if (!sample) return;
      flux = flux.cwiseProduct(sample->weight);
      if (sample->transmitted) medium = medium ? nullptr : &material;
      direction = sample->wi;
      const float offset = 1e-4f * (1.f + hit.point.cwiseAbs().maxCoeff());
      const Vec3 origin =
          hit.point + (direction.dot(hit.geometric_normal) >= 0.f ? offset : -offset) * hit.geometric_normal;
      const std::optional<SurfaceHit> real = tracer_.intersect(Layer::Real, origin, direction);
      const std::optional<SurfaceHit> virtual_hit =
          tracer_.intersect(Layer::Virtual, origin, direction, real ? real->t : std::numeric_limits<float>::infinity());
      const std::optional<SurfaceHit>& next = virtual_hit ? virtual_hit : real;
      if (!next) return;
      if (medium) flux = flux.cwiseProduct(beer_lambert(*medium, (next->point - hit.point).norm()));
      if (flux.maxCoeff() <= 0.f) return;
      if (!scene_.materials[next->material].specular.specular()) {
        record(real, virtual_hit, direction, flux, in_real_virtual, in_real, bounce, rng, parent);
        return;
      }
      if (virtual_hit && in_real) {
        // Without the virtual objects the path goes on to the real surface behind this one.
        if (real) add(*real, direction, flux, false, in_real, bounce, rng, parent);
        in_real = false;
      }
      hit = *next;
    }
  }

 private:
  const MrScene& scene_;
  const RayTracer& tracer_;
  const VplOptions& options_;
  std::vector<Vpl>& out_;
  std::uint32_t light_ = 0;
  std::optional<ConeSearch> cone_;
  std::vector<PendingSegment> pending_;
};

}  // namespace relight::render::vpl_detail
