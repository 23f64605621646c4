#version 450
// One Lloyd step of K-means (kmeans.h, kmeans_vk.h): each invocation assigns one point to its
// nearest centre; the work group adds the fixed-point colour sums, counts and squared distances
// per cluster with integer atomics in shared memory (exact, order-independent) and writes them as
// its row of the partial sums, which the host adds up. Every float expression matches the CPU
// engine's and is `precise` (no fused multiply-add), so both assign identically.
#include "relight/brdf/brdf_shared.h"

layout(local_size_x = RELIGHT_KMEANS_GROUP) in;

layout(std430, set = 0, binding = 0) readonly buffer Points { float points[]; };    // Float3 per point
layout(std430, set = 0, binding = 1) readonly buffer Centres { float centres[]; };  // 4 floats per cluster
layout(std430, set = 0, binding = 2) writeonly buffer Labels { uint labels[]; };
layout(std430, set = 0, binding = 3) writeonly buffer Partials { uint partials[]; };  // clusters * 5 per group
layout(push_constant) uniform Push { KMeansParams params; };

shared uint sums[RELIGHT_KMEANS_MAX_CLUSTERS * RELIGHT_KMEANS_SUMS];

uint quantise(float value, float scale) {
  precise float scaled = value * scale + 0.5;
  return uint(scaled);
}

void main() {
  const uint local = gl_LocalInvocationID.x;
  const uint slots = params.clusters * RELIGHT_KMEANS_SUMS;
  for (uint i = local; i < slots; i += RELIGHT_KMEANS_GROUP) sums[i] = 0u;
  barrier();

  const uint p = gl_GlobalInvocationID.x;
  if (p < params.points) {
    const vec3 x = vec3(points[3 * p], points[3 * p + 1], points[3 * p + 2]);
    float best = uintBitsToFloat(0x7f800000u);  // +infinity
    uint label = 0u;
    for (uint k = 0u; k < params.clusters; ++k) {
      precise float dx = x.x - centres[4 * k];
      precise float dy = x.y - centres[4 * k + 1];
      precise float dz = x.z - centres[4 * k + 2];
      precise float d = (dx * dx + dy * dy) + dz * dz;
      if (d < best) {
        best = d;
        label = k;
      }
    }
    labels[p] = label;
    const uint base = label * RELIGHT_KMEANS_SUMS;
    const float value_scale = float(RELIGHT_KMEANS_VALUE_SCALE);
    atomicAdd(sums[base], quantise(x.x, value_scale));
    atomicAdd(sums[base + 1u], quantise(x.y, value_scale));
    atomicAdd(sums[base + 2u], quantise(x.z, value_scale));
    atomicAdd(sums[base + 3u], 1u);
    atomicAdd(sums[base + 4u], quantise(best, float(RELIGHT_KMEANS_DISTANCE_SCALE)));
  }
  barrier();
  for (uint i = local; i < slots; i += RELIGHT_KMEANS_GROUP) partials[gl_WorkGroupID.x * slots + i] = sums[i];
}
