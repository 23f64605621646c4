#pragma once
// Anti-aliased outlines of virtual objects. DIR's G-buffer takes one sample per pixel (its
// centre), so the virtual coverage c of eq. 5.1's blend is 0 or 1 and the outline is a staircase.
// The path tracer's coverage is the fraction of its samples that hit a virtual object; this gives
// DIR the same fraction where it matters: at pixels whose 3x3 neighbourhood holds both virtual and
// real centre hits, samples x samples sub-pixel rays are cast against the virtual meshes (Embree,
// on the CPU for both backends: the outline is a few hundred pixels), and a sub-sample counts
// when it hits a virtual surface nearer than the real one there. The real surface is the
// reconstruction's (the position map the depth mesh is made of): its distance at the sub-sample is
// bilinear between the pixel centres where they agree within 5 %, else the nearest centre's (a
// depth edge). Cost: only outline pixels, e.g. ~1 ms for the pebble at 640x480 with 16 samples,
// against ~15 ms for the G-buffer itself (dir/frame_640x480_64vpl).
//
// The shading stays per pixel centre: composite.h takes the virtual colour of a partly covered
// pixel from its covered neighbours and the real differential from its uncovered ones, so a blend
// never mixes a virtual colour with a real differential of the same pixel (the halo).
#include "relight/core/image.h"
#include "relight/render/differential_images.h"
#include "relight/render/dir/gbuffer.h"
#include "relight/render/reference/ray_tracer.h"
#include "relight/render/scene/mr_scene.h"

namespace relight::render {

struct EdgeCoverageOptions {
  int samples = 4;  ///< per axis: samples^2 rays per outline pixel
  int threads = 0;
};

/// Outline pixels of `gbuffer` (3x3 neighbourhood with virtual and non-virtual centres).
[[nodiscard]] Mask outline_pixels(const GBuffer& gbuffer);

/// Sets `coverage` at outline pixels to the sub-pixel fraction described above. `virtual_tracer`
/// answers Layer::Virtual; `real_positions` are camera-frame metres (NaN or z <= 0: no surface).
/// Returns the number of outline pixels.
int refine_edge_coverage(CoverageImage& coverage, const GBuffer& gbuffer, const PositionMap& real_positions,
                         const RayTracer& virtual_tracer, const MrCamera& camera,
                         const EdgeCoverageOptions& options = {});

/// The scene's virtual meshes alone (with all materials), for a RayTracer of the virtual layer.
[[nodiscard]] MrScene virtual_part(const MrScene& scene);

}  // namespace relight::render
