// Shared between C++ (depth_box_filter_vk.cpp) and GLSL (shaders/depth_box_filter.comp), so the
// push-constant layout and work-group size cannot drift apart. Plain C preprocessor only (GLSL
// has no #pragma once); in GLSL `uint` is the built-in type, in C++ an alias.
#ifndef RELIGHT_RECONSTRUCT_DEPTH_BOX_FILTER_SHARED_H
#define RELIGHT_RECONSTRUCT_DEPTH_BOX_FILTER_SHARED_H

/// Work-group edge: 16x16 invocations, one per output pixel.
#define RELIGHT_DEPTH_BOX_FILTER_LOCAL_SIZE 16

#ifdef __cplusplus
#include <cstdint>
namespace relight::gpu {
using uint = std::uint32_t;
#endif

/// Push constants of depth_box_filter.comp (std430 rules: two 4-byte members, 8 bytes).
struct DepthBoxFilterParams {
  uint width;   ///< image width in pixels (row length of both buffers)
  uint height;  ///< image height in pixels
};

#ifdef __cplusplus
static_assert(sizeof(DepthBoxFilterParams) == 8);
}  // namespace relight::gpu
#endif

#endif  // RELIGHT_RECONSTRUCT_DEPTH_BOX_FILTER_SHARED_H
