// Shared between C++ (depth_warp_merge_vk.cpp) and GLSL (shaders/depth_warp.comp,
// shaders/depth_merge.comp), so the push-constant layouts and work-group sizes cannot drift
// apart. Plain C preprocessor only (GLSL has no #pragma once); in GLSL `uint` is the built-in type.
#ifndef RELIGHT_RECONSTRUCT_DEPTH_WARP_MERGE_SHARED_H
#define RELIGHT_RECONSTRUCT_DEPTH_WARP_MERGE_SHARED_H

/// Work-group edge of both shaders: 16x16 invocations (one per cell or pixel).
#define RELIGHT_DEPTH_WARP_LOCAL_SIZE 16
/// depth_warp.comp modes: clear the z-buffer; rasterise depths (atomic min); write the weights of
/// the triangles whose depth won.
#define RELIGHT_DEPTH_WARP_CLEAR 0
#define RELIGHT_DEPTH_WARP_DEPTH 1
#define RELIGHT_DEPTH_WARP_WEIGHT 2

#ifdef __cplusplus
#include <cstdint>
namespace relight::gpu {
using uint = std::uint32_t;
#endif

/// Push constants of depth_warp.comp (std430, 96 bytes).
struct DepthWarpParams {
  uint width;
  uint height;
  uint mode;
  uint has_weight;      ///< 0: the previous weights are all 1
  float fx, fy, cx, cy;
  float max_edge_m;
  float max_edge_rel;
  float pad[2];
  float current_from_prev[12];  ///< row-major 3x4
};

/// Push constants of depth_merge.comp (std430, 16 bytes).
struct DepthMergeParams {
  uint width;
  uint height;
  float merge_threshold_m;
  float max_weight;
};

#ifdef __cplusplus
static_assert(sizeof(DepthWarpParams) == 96 && sizeof(DepthMergeParams) == 16);
}  // namespace relight::gpu
#endif

#endif  // RELIGHT_RECONSTRUCT_DEPTH_WARP_MERGE_SHARED_H
