// Shared between C++ (hierarchical_warp_vk.cpp) and GLSL (shaders/warp_pyramid.comp,
// shaders/warp_descend.comp), so the push-constant layouts and work-group size cannot drift apart.
// Plain C preprocessor only (GLSL has no #pragma once); in GLSL `uint` is the built-in type.
#ifndef RELIGHT_RENDER_HIERARCHICAL_WARP_SHARED_H
#define RELIGHT_RENDER_HIERARCHICAL_WARP_SHARED_H

/// Invocations per work group of both shaders (1-D, one per texel or per point).
#define RELIGHT_WARP_LOCAL_SIZE 64
/// Levels the descent can hold (a 8192^2 map has 14).
#define RELIGHT_WARP_MAX_LEVELS 14
/// x and y of a sample when the map has no importance.
#define RELIGHT_WARP_NO_TEXEL 0xffffffffu

#ifdef __cplusplus
#include <cstdint>
namespace relight::gpu {
using uint = std::uint32_t;
#endif

/// Push constants of warp_pyramid.comp: mode 0 copies the map into level 0 (flushing subnormal
/// values), mode 1 sums level `coarse` - 1 into level `coarse`.
struct WarpPyramidParams {
  uint mode;
  uint coarse_side;    ///< texels per side of the level written
  uint fine_offset;    ///< of the level read, in floats into the pyramid
  uint coarse_offset;  ///< of the level written
};

/// Push constants of warp_descend.comp. Samples are 3 words each: x, y, float bits of probability.
struct WarpDescendParams {
  uint size;    ///< side of the map (level 0)
  uint levels;  ///< k + 1
  uint count;   ///< points to warp
  uint pad;
};

#ifdef __cplusplus
static_assert(sizeof(WarpPyramidParams) == 16 && sizeof(WarpDescendParams) == 16);
}  // namespace relight::gpu
#endif

#endif  // RELIGHT_RENDER_HIERARCHICAL_WARP_SHARED_H
