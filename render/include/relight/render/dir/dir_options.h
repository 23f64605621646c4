#pragma once
// The shading settings that differential instant radiosity shares between its renderers: the
// Vulkan renderer and its CPU twin (dir_vk.h) and the exact-visibility reference
// (reference/dir_exact.h), which the first two are tested against.
namespace relight::render {

struct DirOptions {
  float min_distance = 0.1f;  ///< metres; clamps the VPL geometry term
  bool direct = true;
  bool indirect = true;
  int threads = 0;
  /// Real surfaces come from a depth sensor: their points scatter about the mesh that casts the
  /// real layer's shadows by the sensor's depth noise, and at grazing light that scatter is many
  /// shadow-map texels deep (shadow_maps.h, real_surface_tolerance). The real layer's shadow test
  /// on real surfaces tolerates this many standard deviations of it; 0: exact real geometry.
  float real_depth_noise_sigmas = 2.f;
};

}  // namespace relight::render
