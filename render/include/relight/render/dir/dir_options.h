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
};

}  // namespace relight::render
