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
// The CPU mirror of steps 4-5 is shade_dir_from_maps(): the same arithmetic on the same G-buffer and
// atlases, so that a test can hold the GPU to it; the exact-visibility reference of the whole
// method is shade_instant_radiosity() (reference/dir_exact.h).
//
// One pass vs two: `output` lets the same renderer produce only L_rv or only L_r, which is what
// a renderer without the differential formulation has to do twice (bench dir/one_vs_two_pass).
#include <vulkan/vulkan.h>

#include <memory>
#include <span>
#include <vector>

#include "relight/render/differential_images.h"
#include "relight/render/dir/dir_options.h"
#include "relight/render/dir/gbuffer.h"
#include "relight/render/dir/ism.h"
#include "relight/render/dir/shadow_maps.h"

namespace relight::vk {
class VulkanContext;
}

namespace relight::render {

namespace detail {
struct ShadeParams;
}

enum class DirOutput { Both, RealVirtualOnly, RealOnly };

/// Where steps 3-5 (ISMs, shading, merge) run. Rasterisation (steps 1-2) is always Vulkan's.
/// Auto: on the CPU when the Vulkan device is itself a CPU (lavapipe), where relight's CPU code
/// is several times faster than the same per-pixel work through llvmpipe (platform.md; bench
/// dir/frame_640x480_*: cpu_mirror_ms), on the GPU otherwise.
enum class DirBackend { Auto, Gpu, Cpu };

struct DirVkOptions {
  DirOptions shading{};      ///< min_distance, direct, indirect (threads: unused)
  int shadow_tile = 512;     ///< texels per side of a primary light's shadow-map view
  IsmOptions ism{};
  int interleave = 4;        ///< n: n x n VPL subsets; 1 = every pixel sees every VPL
  DirOutput output = DirOutput::Both;
  DirBackend backend = DirBackend::Auto;
};

/// Milliseconds per step of the last render: GPU time from timestamps (0 without timestamp
/// support) for Vulkan steps, wall time for steps the CPU ran (`cpu_shading`; merge_ms is then
/// part of shading_ms). Note: llvmpipe's timestamps do not bracket compute dispatches reliably.
struct DirVkTimings {
  double gbuffer_ms = 0, shadow_maps_ms = 0, ism_ms = 0, shading_ms = 0, merge_ms = 0, total_ms = 0;
  bool cpu_shading = false;
};

class DirRendererVk {
 public:
  /// Throws relight::Error when the device cannot rasterise and compute on one queue.
  DirRendererVk(vk::VulkanContext& context, int width, int height);
  ~DirRendererVk();
  DirRendererVk(const DirRendererVk&) = delete;
  DirRendererVk& operator=(const DirRendererVk&) = delete;

  /// Geometry, materials, lights and the ISM point pools (options.ism's counts and seed).
  void set_scene(const MrScene& scene, const DirVkOptions& options = {});
  [[nodiscard]] DifferentialImages render(const MrCamera& camera, std::span<const Vpl> vpls,
                                          const DirVkOptions& options = {});
  [[nodiscard]] const DirVkTimings& last_timings() const;

  // The intermediate results of the last render, read back (for tests and debugging views).
  /// The G-buffer of the last render; valid until the next render.
  [[nodiscard]] const GBuffer& last_gbuffer() const;
  [[nodiscard]] std::vector<float> last_shadow_atlas() const;
  [[nodiscard]] std::vector<float> last_ism_atlas() const;
  [[nodiscard]] const ShadowLayout& shadow_layout() const;
  [[nodiscard]] const IsmPointPools& ism_points() const;

 private:
  void record_shading(VkCommandBuffer cmd, const detail::ShadeParams& params, const DirVkOptions& options);
  [[nodiscard]] DifferentialImages shade_on_cpu(const MrCamera& camera, std::span<const Vpl> vpls,
                                                const DirVkOptions& options);

  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The whole method without a GPU, step for step the same algorithm (ray-cast G-buffer and
/// shadow maps, CPU ISMs, shade_dir_from_maps): the fallback where no Vulkan device exists.
/// `vpls` as for DirRendererVk::render.
[[nodiscard]] DifferentialImages render_dir_cpu(const MrScene& scene, const MrCamera& camera, std::span<const Vpl> vpls,
                                                const DirVkOptions& options = {}, GBuffer* gbuffer_out = nullptr);

/// The shading pass on the CPU, from the same inputs as the GPU's (`virtual_bounds`: the ISM
/// point pools' IsmPointPools::virtual_bounds).
[[nodiscard]] DifferentialImages shade_dir_from_maps(const GBuffer& gbuffer, const MrScene& scene,
                                                     const Eigen::Vector3f& camera_centre, const ShadowLayout& layout,
                                                     std::span<const float> shadow_atlas, std::span<const Vpl> vpls,
                                                     std::span<const float> ism_atlas,
                                                     const Eigen::Vector4f& virtual_bounds, const DirVkOptions& options);

}  // namespace relight::render
