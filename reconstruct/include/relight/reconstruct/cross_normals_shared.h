// Shared between C++ (cross_normals_vk.cpp) and GLSL (shaders/cross_normals.comp), so the
// push-constant layout and work-group size cannot drift apart. Plain C preprocessor only (GLSL
// has no #pragma once); in GLSL `uint` is the built-in type, in C++ an alias.
#ifndef RELIGHT_RECONSTRUCT_CROSS_NORMALS_SHARED_H
#define RELIGHT_RECONSTRUCT_CROSS_NORMALS_SHARED_H

/// Work-group edge: 16x16 invocations, one per output pixel.
#define RELIGHT_CROSS_NORMALS_LOCAL_SIZE 16

#ifdef __cplusplus
#include <cstdint>
namespace relight::gpu {
using uint = std::uint32_t;
#endif

/// Push constants of cross_normals.comp (std430: nine 4-byte members, 36 bytes). The float
/// intrinsics are computed on the host exactly as positions_from_depth does (1/fx in double,
/// then rounded), so both backends multiply the same float values.
struct CrossNormalsParams {
  uint width;          ///< image width in pixels (row length of every buffer)
  uint height;         ///< image height in pixels
  int stride;          ///< s of eq. 4.4–4.5 (>= 1)
  float max_jump_rel;  ///< discontinuity threshold, fraction of the centre's z
  float inv_fx;        ///< float(1.0 / fx)
  float inv_fy;        ///< float(1.0 / fy)
  float cx;            ///< principal point, pixels
  float cy;
  uint centred;        ///< CrossNormalOptions::centred (0 or 1)
};

#ifdef __cplusplus
static_assert(sizeof(CrossNormalsParams) == 36);
}  // namespace relight::gpu
#endif

#endif  // RELIGHT_RECONSTRUCT_CROSS_NORMALS_SHARED_H
