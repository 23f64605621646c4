#pragma once
// Rasterised reflective shadow maps (reflective_shadow_map.h) on Vulkan: each RSM is a G-buffer
// pass (gbuffer_vk.h) from the spot light through its RsmView, drawn through the layers the RSM
// sees: a virtual light's one RSM through both layers; a real light's real RSM through the real
// layer and its virtual RSM through the virtual layer, both drawn, so that the virtual RSM keeps
// only the virtual surfaces in front of the real ones and the real RSM knows which of its texels a
// virtual surface hides (occluded_by_virtual). The per-texel direction, flux and importance come
// from assemble_reflective_shadow_maps, as in the ray-cast reference, reflective_shadow_maps_cpu,
// which these maps equal texel for texel away from triangle edges; the surface normal is the
// G-buffer's, which faces the light (the ray-cast hit's shading normal is not flipped; VPL
// generation orients normals itself).
//
// Reads: the MrScene (set_scene, uploaded per layer), a spot light of it per render.
// Writes: std::vector<ReflectiveShadowMap>, as reflective_shadow_maps_cpu.
#include <memory>
#include <vector>

#include "relight/render/scene/mr_scene.h"
#include "relight/render/vpl/reflective_shadow_map.h"

namespace relight::vk {
class VulkanContext;
}

namespace relight::render {

class ReflectiveShadowMapsVk {
 public:
  /// Throws relight::Error when the device has no queue for graphics and compute.
  explicit ReflectiveShadowMapsVk(vk::VulkanContext& context);
  ~ReflectiveShadowMapsVk();
  ReflectiveShadowMapsVk(const ReflectiveShadowMapsVk&) = delete;
  ReflectiveShadowMapsVk& operator=(const ReflectiveShadowMapsVk&) = delete;

  /// Uploads the scene's triangles (per layer); must come before render and after every change.
  void set_scene(const MrScene& scene);
  /// The RSMs of spot light `light` of the scene given to set_scene, `size`² texels each, with
  /// the contract (and the errors) of reflective_shadow_maps_cpu.
  [[nodiscard]] std::vector<ReflectiveShadowMap> render(const MrScene& scene, std::size_t light, int size);
  /// GPU time of the last render's passes, milliseconds (0 without timestamp support).
  [[nodiscard]] double last_gpu_ms() const;
  /// The GPU milliseconds of every render since the last call: what a stage that renders the
  /// RSMs of several lights per frame reports.
  double take_gpu_ms();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace relight::render
