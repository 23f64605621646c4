#pragma once
// Differential instant radiosity on the CPU (Knecht et al., ISMAR 2010; dissertation §5.2): the
// reference that the Vulkan renderer is tested against. It shades one sample per pixel (the
// G-buffer: the nearest real or virtual surface through the pixel centre) with every primary
// light and every VPL (vpl.h), using exact visibility from Embree where the GPU uses imperfect
// shadow maps.
//
// Reads an MrScene, an MrCamera and the VPLs; writes L_rv, L_r and the virtual coverage (0 or 1):
//   direct   (eqs. 5.1-5.5)  L_rv += L_o min(V_r, V_v)            L_r += L_o r(light) r(p) V_r
//   indirect (eqs. 5.6-5.8)  L_rv += L_o (1 - ir(VPL)) min(V_r, V_v)
//                            L_r  += L_o r(x̄) r(VPL) r(p) V_r
// with V_r / V_v the visibility through the real / virtual layer and the VPL flags of vpl.h
// (1 - ir = in_real_virtual, r(x̄) r(VPL) = in_real). Surface emission is added as seen.
//
// The VPL singularity: the geometry term cos cos / d^2 is evaluated with d^2 clamped to at least
// `min_distance`^2, the usual bound of instant radiosity (it darkens concave corners closer
// than min_distance to a VPL instead of letting single VPLs flare up).
#include <vector>

#include "relight/render/dir/dir_options.h"
#include "relight/render/reference/path_tracer.h"
#include "relight/render/vpl/vpl.h"

namespace relight::render {

[[nodiscard]] DifferentialImages shade_instant_radiosity(const MrScene& scene, const RayTracer& tracer,
                                                         const MrCamera& camera, const std::vector<Vpl>& vpls,
                                                         const DirOptions& options = {});

}  // namespace relight::render
