#pragma once
// Differential instant radiosity on Vulkan (Knecht et al., ISMAR 2010; dissertation chapter 5):
// per frame, in one command buffer,
//   1. the G-buffer of the camera (gbuffer_vk.h), r(p) in the sign of the distance;
//   2. the shadow-map atlas of the primary lights, real and virtual layer (shadow_maps.h);
//   3. the imperfect shadow maps of the VPLs, real and virtual layer (ism.h);
//   4. one shading dispatch that writes L_rv and L_r together (dir_shade.comp, eqs. 5.1-5.8),
//      each pixel lit by 1 / interleave^2 of the VPLs (interleaved sampling, Segovia et al. 2006);
//   5. a geometry-aware merge of the interleaved indirect light (dir_merge.comp).
// Reads an MrScene (set_scene), an MrCamera and the VPLs of vpl.h; writes DifferentialImages.
//
// The CPU twin (dir.h: render_dir_cpu, and shade_dir_from_maps for steps 4-5 on the same G-buffer
// and atlases) is what a test holds the GPU to; the exact-visibility reference of the whole
// method is shade_instant_radiosity() (reference/dir_exact.h). This header names no Vulkan type.
//
// One pass vs two: `output` lets the same renderer produce only L_rv or only L_r, which is what
// a renderer without the differential formulation has to do twice (bench dir/one_vs_two_pass).
#include <future>
#include <memory>
#include <span>
#include <vector>

#include "relight/render/dir/dir.h"

namespace relight::vk {
class VulkanContext;
}

namespace relight::render {

/// Milliseconds per step of the last render: GPU time from timestamps (0 without timestamp
/// support) for Vulkan steps, wall time for steps the CPU ran (`cpu_shading`; merge_ms is then
/// part of shading_ms). Note: llvmpipe's timestamps do not bracket compute dispatches reliably.
struct DirVkTimings {
  double gbuffer_ms = 0, shadow_maps_ms = 0, ism_ms = 0, shading_ms = 0, merge_ms = 0, total_ms = 0;
  bool cpu_shading = false;
  double specular_ms = 0;  ///< CPU wall time of the reflective/refractive step (specular_shading.h); 0 without
};

class DirRendererVk {
 public:
  /// Throws relight::Error when the device cannot rasterise and compute on one queue.
  DirRendererVk(vk::VulkanContext& context, int width, int height);
  ~DirRendererVk();
  DirRendererVk(const DirRendererVk&) = delete;
  DirRendererVk& operator=(const DirRendererVk&) = delete;

  /// Geometry, materials, lights and the ISM point pools (options.ism's counts and seed).
  void set_scene(const MrScene& scene, const DirRenderOptions& options = {});
  [[nodiscard]] DifferentialImages render(const MrCamera& camera, std::span<const Vpl> vpls,
                                          const DirRenderOptions& options = {});
  [[nodiscard]] const DirVkTimings& last_timings() const;

  // The intermediate results of the last render, read back (for tests and debugging views).
  /// The G-buffer of the last render; valid until the next render.
  [[nodiscard]] const GBuffer& last_gbuffer() const;
  [[nodiscard]] std::vector<float> last_shadow_atlas() const;
  [[nodiscard]] std::vector<float> last_ism_atlas() const;
  [[nodiscard]] const ShadowLayout& shadow_layout() const;
  /// What the last render's mirrors and glass show, for the composite (empty without them).
  [[nodiscard]] const SpecularBackProjection& last_back_projection() const;
  [[nodiscard]] const IsmPointPools& ism_points() const;

 private:
  [[nodiscard]] DifferentialImages download_images() const;
  /// The last render's shadow atlas for the host to read, without a copy where the device's
  /// memory is host-visible; valid until the next read-back.
  [[nodiscard]] std::span<const float> shadow_atlas_view() const;
  struct TimedIsmAtlas;  ///< the CPU's ISM atlas and the milliseconds it took
  [[nodiscard]] DifferentialImages shade_on_cpu(const MrCamera& camera, std::span<const Vpl> vpls,
                                                std::future<TimedIsmAtlas>& ism, const DirRenderOptions& options);

  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace relight::render
