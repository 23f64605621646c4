// Shared between C++ (hierarchical_warp_vk.cpp) and GLSL (shaders/warp_pyramid.comp,
// shaders/warp_descend.comp), so the push-constant layouts and work-group size cannot drift apart.
// Plain C preprocessor only (GLSL has no #pragma once); in GLSL `uint` is the built-in type.
#ifndef RELIGHT_RENDER_HIERARCHICAL_WARP_SHARED_H
#define RELIGHT_RENDER_HIERARCHICAL_WARP_SHARED_H

/// Invocations per work group of warp_descend.comp (1-D, one per point).
#define RELIGHT_WARP_LOCAL_SIZE 64
/// Edge of warp_pyramid.comp's square work group (one invocation per block of the level read).
#define RELIGHT_WARP_PYRAMID_GROUP 8
/// Levels one warp_pyramid.comp dispatch writes at most (each invocation sums an 8x8 block).
#define RELIGHT_WARP_LEVELS_PER_DISPATCH 3
/// Levels the descent can hold (a 8192^2 map has 14).
#define RELIGHT_WARP_MAX_LEVELS 14
/// x and y of a sample when the map has no importance.
#define RELIGHT_WARP_NO_TEXEL 0xffffffffu

#ifdef __cplusplus
#include <cstdint>
namespace relight::gpu {
using uint = std::uint32_t;
#endif

/// Push constants of warp_pyramid.comp: mode 0 reads the importance map (and writes it as level
/// 0, flushing subnormal values), mode 1 a level of the pyramid; either way the next
/// `level_count` (1..3) levels are written.
struct WarpPyramidParams {
  uint mode;
  uint fine_side;    ///< texels per side of the level read
  uint fine_offset;  ///< of the level read, in floats into the pyramid (mode 1)
  uint level_count;
  uint offsets[4];   ///< of the levels written, in floats into the pyramid (the 4th is padding)
};

/// Push constants of warp_descend.comp. Samples are 3 words each: x, y, float bits of probability.
struct WarpDescendParams {
  uint size;    ///< side of the map (level 0)
  uint levels;  ///< k + 1
  uint count;   ///< points to warp
  uint pad;
};

#ifdef __cplusplus
static_assert(sizeof(WarpPyramidParams) == 32 && sizeof(WarpDescendParams) == 16);
}  // namespace relight::gpu
#endif

#endif  // RELIGHT_RENDER_HIERARCHICAL_WARP_SHARED_H
