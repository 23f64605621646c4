#pragma once
// Caustic light paths for the differential path tracer (path_tracer.h): the light that reaches a
// surface through mirrors and glass from the point, spot and directional lights (Knecht et al.
// 2013's LS+DE and LS+D+E paths: caustics and the light they bounce on).
//
// Why a second technique: a camera path meets a delta light only by next-event estimation from a
// non-specular vertex, so every path whose vertex next to the light is specular (light -> mirror
// or glass -> ...) has probability zero there. Light tracing (Veach's thesis §10.2; Dutré et al.)
// finds exactly those: a path leaves the light, must first hit a specular surface, follows
// specular bounces (Fresnel choice, Beer-Lambert inside glass, specular_bsdf.h in importance
// mode) and, at every non-specular vertex y, is connected to the pinhole camera and splatted into
// the pixel y projects to,
//
//   I_pixel += beta f(y; wi, wc) |n.wc| / d^2 * fx fy / cos^3(theta_c) / N
//
// (beta the path's flux weight, wc towards the camera at distance d, theta_c the angle to the
// optical axis: the pinhole's importance per pixel, N the light paths per light and pass). It then
// continues with Phong sampling (bounce limit and roulette as the camera paths), so light bounced
// from caustics is found too. The two techniques split the paths by the vertex next to the
// light (specular: here; non-specular: the camera paths), so nothing is counted twice and the sum
// is unbiased. Paths that need a specular vertex at both ends (a caustic seen in a mirror, E S D S L)
// have probability zero in both with point lights and a pinhole; they are missing, as in every
// unbiased path tracer without photon density estimation.
//
// Emission is importance-sampled towards the specular objects only: directions from a point or
// spot light uniformly in the cone around the bounding sphere of the specular triangles (every
// direction that can hit one first lies in it), a directional light's rays over a disc of that
// sphere's radius across its direction, started outside the whole scene.
//
// Differential: each path is traced twice with the same random numbers, in the whole scene (L_rv;
// every light) and in the real one (L_r; real lights only, virtual meshes invisible), and each
// splat needs the camera to be visible in that version. While a path meets only real surfaces the
// two versions are identical, so their difference stays exactly zero there.
#include <cstdint>
#include <vector>

#include "relight/render/reference/path_tracer.h"
#include "relight/render/reference/ray_tracer.h"

namespace relight::render::detail {

class CausticLightTracer {
 public:
  CausticLightTracer(const RayTracer& tracer, const PathTracerOptions& options);

  /// Whether the scene has any specular triangle and any light (else trace() adds nothing).
  [[nodiscard]] bool active() const { return active_; }

  /// Traces `paths` light paths per light for progressive pass `pass` and adds their splats,
  /// each already divided by `paths`, to the per-pixel RGB sums (3 per pixel, row-major) of
  /// `camera`'s image. The result depends on the seed, the pass and `paths` only, not on the
  /// threads. Returns the rays traced.
  std::uint64_t trace(const MrCamera& camera, std::uint64_t paths, std::uint64_t pass, std::vector<double>& sum_rv,
                      std::vector<double>& sum_r) const;

 private:
  const RayTracer& tracer_;
  const PathTracerOptions& options_;
  BoundingSphere specular_bounds_;
  BoundingSphere scene_bounds_;
  bool active_ = false;
};

}  // namespace relight::render::detail
