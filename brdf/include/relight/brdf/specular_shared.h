// Shared between C++ and the GLSL specular-objective shader (specular_objective_vk.h), so that
// the work-group size, the buffer layouts and the push constants cannot drift apart.
// Plain C preprocessor only (GLSL has no #pragma once).
#ifndef RELIGHT_SPECULAR_SHARED_H
#define RELIGHT_SPECULAR_SHARED_H

/// Samples per work group (one invocation per sample and candidate).
#define RELIGHT_SPECULAR_GROUP 256
/// Most lights the shader reads (the fit's light set is small: importance-sampled lights).
#define RELIGHT_SPECULAR_MAX_LIGHTS 64
/// Most lights whose positions a candidate moves (SpecularOptions::moving_lights <= 2).
#define RELIGHT_SPECULAR_MAX_MOVING 2
/// vec4s per sample: radiance, position, normal (xyz each).
#define RELIGHT_SPECULAR_SAMPLE_VEC4S 3
/// vec4s per light: (vector, 1 for a point light else 0), (power, 0).
#define RELIGHT_SPECULAR_LIGHT_VEC4S 2
/// vec4s per candidate: (k_s, n, 0, 0), then one offset per moving light.
#define RELIGHT_SPECULAR_CANDIDATE_VEC4S (1 + RELIGHT_SPECULAR_MAX_MOVING)

#ifdef __cplusplus
#include <cstdint>
namespace relight::gpu {
using uint = std::uint32_t;
struct vec4 {
  float x, y, z, w;
};
#endif

/// Push constants of brdf_specular_objective.comp (std430: 48 bytes).
struct SpecularObjectiveParams {
  uint samples;
  uint lights;
  uint moving;  ///< the first `moving` lights move by the candidate's offsets
  uint groups;  ///< work groups per candidate (row length of the partial sums)
  vec4 kd;
  vec4 ambient;
};

#ifdef __cplusplus
static_assert(sizeof(SpecularObjectiveParams) == 48);
}  // namespace relight::gpu
#endif

#endif  // RELIGHT_SPECULAR_SHARED_H
