#pragma once
// Differential instant radiosity (Knecht et al., ISMAR 2010; dissertation chapter 5), whatever
// runs it: the options every backend takes, and the CPU twin of the Vulkan renderer (dir_vk.h).
//
// render_dir_cpu() is the whole method without a GPU, step for step the Vulkan renderer's
// algorithm (ray-cast G-buffer and shadow maps, CPU imperfect shadow maps, shade_dir_from_maps);
// shade_dir_from_maps() is its shading pass (eqs. 5.1-5.8 with interleaved sampling and the
// geometry-aware merge) on the same G-buffer and atlases the GPU shades from, so that a test can
// hold the GPU to it. Reads an MrScene, an MrCamera and the VPLs (vpl/vpl.h); writes
// DifferentialImages (L_rv, L_r, coverage, their indirect parts). Emitter VPLs (the last of the
// list, vpl.h) are direct light: every pixel sums all of them, outside the interleaving, the
// merge and the indirect parts that temporal smoothing blends. Pixels on mirrors and glass
// take the light of what they reflect and refract (specular_shading.h, both renderers).
#include <span>

#include "relight/render/differential_images.h"
#include "relight/render/dir/caustic_photons.h"
#include "relight/render/dir/dir_options.h"
#include "relight/render/dir/gbuffer.h"
#include "relight/render/dir/ism.h"
#include "relight/render/dir/shadow_maps.h"
#include "relight/render/dir/specular_back_projection.h"

namespace relight::render {

enum class DirOutput { Both, RealVirtualOnly, RealOnly };

/// Where steps 3-5 (ISMs, shading, merge) run. Rasterisation (steps 1-2) is always Vulkan's.
/// Auto: on the CPU when the Vulkan device is itself a CPU (lavapipe), where relight's CPU code
/// is several times faster than the same per-pixel work through llvmpipe (docs/platform.md; bench
/// dir/frame_640x480_*: cpu_mirror_ms), on the GPU otherwise.
enum class DirBackend { Auto, Gpu, Cpu };

struct DirRenderOptions {
  DirOptions shading{};      ///< min_distance, direct, indirect (threads: unused)
  int shadow_tile = 512;     ///< texels per side of a primary light's shadow-map view
  IsmOptions ism{};
  int interleave = 4;        ///< n: n x n VPL subsets; 1 = every pixel sees every VPL
  DirOutput output = DirOutput::Both;
  DirBackend backend = DirBackend::Auto;
  CausticOptions caustics{};  ///< the light mirrors and glass focus (caustic_photons.h)
};

/// The whole method without a GPU, step for step the same algorithm (ray-cast G-buffer and
/// shadow maps, CPU ISMs, shade_dir_from_maps): the fallback where no Vulkan device exists.
/// `vpls` as for DirRendererVk::render. `back_projection_out`: what mirrors and glass show, for
/// the composite (specular_back_projection.h; empty without them).
[[nodiscard]] DifferentialImages render_dir_cpu(const MrScene& scene, const MrCamera& camera, std::span<const Vpl> vpls,
                                                const DirRenderOptions& options = {}, GBuffer* gbuffer_out = nullptr,
                                                SpecularBackProjection* back_projection_out = nullptr);

/// The shading pass on the CPU, from the same inputs as the GPU's (`ism_points`: the pools the
/// ISM atlas was splatted from, for their bounds).
[[nodiscard]] DifferentialImages shade_dir_from_maps(const GBuffer& gbuffer, const MrScene& scene,
                                                     const Eigen::Vector3f& camera_centre, const ShadowLayout& layout,
                                                     std::span<const float> shadow_atlas, std::span<const Vpl> vpls,
                                                     std::span<const float> ism_atlas, const IsmPointPools& ism_points,
                                                     const DirRenderOptions& options);

}  // namespace relight::render
