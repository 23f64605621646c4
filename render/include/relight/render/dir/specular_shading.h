#pragma once
// DIR's light at reflective and refractive objects (Knecht et al., TVCG 2013, §4.1.1, eqs. 3-5):
//
//   L'_rv = sum_ls L_refl(ls) + L_refr(ls)
//   L'_r  = sum_ls L_refl(ls) real(ls, p_refl) + L_refr(ls) real(ls, p_refr),
//   real(ls, p) = r(ls) and r(p),
//
// where L_refl and L_refr are the radiance of the surfaces the reflected and the refracted ray
// end on (specular_gbuffer.h), lit by every primary light and VPL, times their branch's weight
// (Fresnel, eta^2, T_c). The surfaces are shaded by DIR's own pass (dir.h, shade_dir_from_maps:
// shadow maps, ISMs, interleaving and the geometry-aware merge over the secondary G-buffer), each
// seen from its branch's eye; a branch that leaves the scene sees the environment (the paper's
// L_env), which is real, so it cancels in L'_rv - L'_r as the paper's separate L_env buffer does.
//
// At a real mirror or glass (add_real_model) relight departs from eq. 4: where a branch ends on a
// virtual object, L'_r is not zero but the light of the branch traced again in the real world
// (specular_gbuffers_cpu's real_world: what the camera sees in the mirror behind the object), so
// that the composite's Delta L' replaces that surface by the object instead of adding the object
// to it (add_specular_light).
//
// Reads SpecularGBuffers, the MrScene and the same maps and VPLs as shade_dir_from_maps; writes
// DifferentialImages holding L'_rv and L'_r (with their indirect parts) at the specular pixels,
// zero elsewhere, and each branch's L_r for the back-projection (specular_back_projection.h). put_specular_light()
// writes them into DIR's images at those pixels, as the paper's "in practice L_r and L'_r are one buffer".
#include <span>

#include "relight/render/differential_images.h"
#include "relight/render/dir/caustic_photons.h"
#include "relight/render/dir/dir.h"
#include "relight/render/dir/specular_back_projection.h"
#include "relight/render/dir/specular_gbuffer.h"

namespace relight::render {

/// L'_rv and L'_r, and each branch's unweighted L_r (for the back-projection's fallback).
struct SpecularLight {
  DifferentialImages light;
  RadianceImage reflected_real, refracted_real;
};

/// `photons`: the frame's caustics (the lights' and the VPLs'), which the surfaces seen in mirrors
/// and glass show too (none: no caustics).
[[nodiscard]] SpecularLight shade_specular_from_maps(const SpecularGBuffers& specular, const MrScene& scene,
                                                     const ShadowLayout& layout, std::span<const float> shadow_atlas,
                                                     std::span<const Vpl> vpls, std::span<const float> ism_atlas,
                                                     const IsmPointPools& ism_points, const DirRenderOptions& options,
                                                     std::span<const CausticPhotons> photons = {});

/// The whole step on the CPU, where both DIR renderers call it: the caustics of the frame
/// (caustic_photons.h, options.caustics: the lights' photons and those of `vpls`) gathered at
/// `gbuffer`; the secondary G-buffers of
/// `gbuffer` (specular_gbuffers_cpu over `tracer`), shaded with their caustics
/// (shade_specular_from_maps), put into `images` (put_specular_light). Returns their
/// back-projection into the camera image (specular_back_projection.h; empty where no pixel is
/// specular), for the composite.
SpecularBackProjection add_specular_light(DifferentialImages& images, const RayTracer& tracer, const MrCamera& camera,
                                          const GBuffer& gbuffer, const ShadowLayout& layout,
                                          std::span<const float> shadow_atlas, std::span<const Vpl> vpls,
                                          std::span<const float> ism_atlas, const IsmPointPools& ism_points,
                                          const DirRenderOptions& options);

/// L'_rv and L'_r (and their indirect parts) in place of `images`' values at the specular pixels.
void put_specular_light(DifferentialImages& images, const DifferentialImages& specular_light,
                        const SpecularGBuffers& specular);

}  // namespace relight::render
