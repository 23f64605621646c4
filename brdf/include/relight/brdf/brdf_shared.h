// Shared between C++ and the GLSL K-means shader, so that the work-group size, the fixed-point
// scales and the layout of the per-group partial sums cannot drift apart.
// Plain C preprocessor only (GLSL has no #pragma once).
#ifndef RELIGHT_BRDF_SHARED_H
#define RELIGHT_BRDF_SHARED_H

/// Points per work group of the K-means step (one invocation per point).
#define RELIGHT_KMEANS_GROUP 256
/// Most clusters the shader's shared-memory sums hold.
#define RELIGHT_KMEANS_MAX_CLUSTERS 16
/// uints per cluster in a group's partial sums: colour sum (3), count, squared-distance sum.
#define RELIGHT_KMEANS_SUMS 5
/// Features are clamped to [0, RELIGHT_KMEANS_FEATURE_MAX] (k_d rarely exceeds 1).
#define RELIGHT_KMEANS_FEATURE_MAX 2.0
/// Fixed-point scales of the sums: a group's colour sum is at most 256 * 2 * 2^22 = 2^31 and its
/// squared-distance sum at most 256 * 12 * 2^20 < 2^32, so both fit a uint. Integer sums are
/// exact and independent of the order of addition, which makes the CPU and GPU sums identical.
#define RELIGHT_KMEANS_VALUE_SCALE 4194304.0
#define RELIGHT_KMEANS_DISTANCE_SCALE 1048576.0

#ifdef __cplusplus
#include <cstdint>
namespace relight::gpu {
using uint = std::uint32_t;
#endif

/// Push constants of brdf_kmeans.comp (std430: 8 bytes); centres come in a storage buffer.
struct KMeansParams {
  uint points;
  uint clusters;
};

#ifdef __cplusplus
static_assert(sizeof(KMeansParams) == 8);
}  // namespace relight::gpu
#endif

#endif  // RELIGHT_BRDF_SHARED_H
