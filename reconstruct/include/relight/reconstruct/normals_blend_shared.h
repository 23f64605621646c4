// Shared between C++ (normals_blend_vk.cpp) and GLSL (shaders/normals_blend.comp,
// shaders/normals_fill_holes.comp): push constants and work-group size. Plain C preprocessor only.
#ifndef RELIGHT_RECONSTRUCT_NORMALS_BLEND_SHARED_H
#define RELIGHT_RECONSTRUCT_NORMALS_BLEND_SHARED_H

#define RELIGHT_NORMALS_BLEND_LOCAL_SIZE 16

#ifdef __cplusplus
#include <cstdint>
namespace relight::gpu {
using uint = std::uint32_t;
#endif

/// Push constants of normals_blend.comp (std430: 30 four-byte members, 120 bytes <= 128).
struct NormalsBlendParams {
  float prev_from_current[12];  ///< row-major 3x4 rigid transform, float like the CPU's Rigid
  float current_from_prev[9];   ///< row-major 3x3 rotation
  float fx;
  float fy;
  float cx;
  float cy;
  float blend_base;      ///< c_B of eq. 4.8
  float disocclusion_m;  ///< depth change that resets the history
  uint width;            ///< full-resolution image size
  uint height;
  uint levels;  ///< pyramid levels uploaded (>= 1)
};

/// Push constants of normals_fill_holes.comp.
struct NormalsFillParams {
  uint width;
  uint height;
};

#ifdef __cplusplus
static_assert(sizeof(NormalsBlendParams) == 120);
static_assert(sizeof(NormalsFillParams) == 8);
}  // namespace relight::gpu
#endif

#endif  // RELIGHT_RECONSTRUCT_NORMALS_BLEND_SHARED_H
