#pragma once
// The secondary G-buffers of DIR's reflective and refractive objects (Knecht et al., TVCG 2013,
// §4.1 and §5.1: GBuf_refl and GBuf_refr; the dissertation's §5.3): for every camera pixel whose
// primary surface (gbuffer.h) has a specular material (specular_material.h), the diffuse
// surface its reflected ray and its refracted ray end on, stored like a G-buffer so that DIR's
// shading pass lights them with every primary light and VPL (specular_shading.h, eqs. 3-5).
//
// Reads the MrScene through a RayTracer (real and virtual layers), the camera and the primary
// G-buffer; writes SpecularGBuffers. Where this departs from the paper: the paper rasterises
// the two G-buffers with Popescu's reflection impostors and Wyman's two-sided refraction (the
// back face from a depth map, one exit, no total internal reflection); relight traces both
// rays exactly (Embree), through the object and out again, with total internal reflection and
// mirrors seeing mirrors. A branch follows one path: at its first vertex the reflection or the
// refraction by the branch, at every later specular vertex the stronger of the two lobes (the
// exit refraction of glass, its reflection beyond the critical angle), its weight multiplied by
// that lobe's Fresnel factor; the weaker lobe's light (a few percent inside glass) is not
// followed. After `max_vertices` specular vertices a branch is dropped (weight zero).
#include "relight/core/image.h"
#include "relight/render/dir/gbuffer.h"
#include "relight/render/reference/ray_tracer.h"
#include "relight/render/scene/mr_scene.h"

namespace relight::render {

/// One branch (reflected or refracted) of every specular pixel.
struct SpecularBranch {
  /// The diffuse surface the branch ends on, as gbuffer_cpu() stores a camera ray's hit (its
  /// normal facing the branch's last segment; `distance` that segment's length); empty (distance
  /// 0) where the branch leaves the scene, is dropped, or the pixel has no such branch.
  GBuffer gbuffer;
  /// What that surface's radiance is multiplied by on its way to the camera, per channel: the
  /// Fresnel factor of every specular vertex, the eta^2 radiance factor of every refraction and
  /// Beer-Lambert's T_c over every segment inside a dielectric (the paper's eta_1 and eta_2 T_c).
  /// Set where the branch leaves the scene (it then sees the environment); 0 where the pixel has
  /// no such branch.
  RadianceImage weight;
  /// Where the branch's last segment starts: the surface is seen from there (its view direction).
  PositionMap eye;
};

struct SpecularGBuffers {
  SpecularBranch reflected, refracted;
  Mask specular;   ///< 1 where the primary surface has a specular material
  int pixels = 0;  ///< how many

  static constexpr const char* type_name = "SpecularGBuffers";
};

struct SpecularTraceOptions {
  int max_vertices = 8;  ///< specular vertices one branch may pass (entry, exit, internal reflections)
  int threads = 0;
  /// Trace in the real world alone (virtual meshes invisible), from the real specular pixels
  /// only: what a real mirror or glass shows without the virtual objects, L'_r's own branches
  /// (specular_shading.h).
  bool real_world = false;
};

/// Whether any surface of `scene` has a specular material (then DIR traces secondary G-buffers).
[[nodiscard]] bool has_specular_surfaces(const MrScene& scene);

/// The two branches of every pixel of `primary` whose surface is specular. `primary` must be
/// the G-buffer of `camera` over the same scene as `tracer`.
[[nodiscard]] SpecularGBuffers specular_gbuffers_cpu(const RayTracer& tracer, const MrCamera& camera,
                                                     const GBuffer& primary, const SpecularTraceOptions& options = {});

}  // namespace relight::render
