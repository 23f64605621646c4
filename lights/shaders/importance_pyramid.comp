#version 450
// One level of the importance sum pyramid (importance_sampling.h, step 1); the GPU twin of
// ImportancePyramid::build. `precise` forbids fused multiply-adds and reassociation, so the
// values match the CPU reference bit for bit.
#include "relight/lights/importance_shared.h"

layout(local_size_x = RELIGHT_IMPORTANCE_PYRAMID_LOCAL_SIZE, local_size_y = RELIGHT_IMPORTANCE_PYRAMID_LOCAL_SIZE) in;

layout(std430, set = 0, binding = 0) readonly buffer Radiance { float radiance[]; };    // RGB per pixel
layout(std430, set = 0, binding = 1) readonly buffer SolidAngle { float solid_angle[]; };
layout(std430, set = 0, binding = 2) buffer Pyramid { float pyramid[]; };               // finest level first
layout(push_constant) uniform Push { ImportancePyramidParams params; };

float non_negative(float value) { return value > 0.0 ? value : 0.0; }  // NaN -> 0

void main() {
  const uint col = gl_GlobalInvocationID.x;
  const uint row = gl_GlobalInvocationID.y;
  const uint size = params.level_size;
  if (col >= size || row >= size) return;

  precise float value = 0.0;
  if (params.level == 0u) {
    if (col < params.width && row < params.height) {
      const uint pixel = row * params.width + col;
      precise float lum = 0.2126 * non_negative(radiance[3u * pixel]) + 0.7152 * non_negative(radiance[3u * pixel + 1u]) +
                          0.0722 * non_negative(radiance[3u * pixel + 2u]);
      value = lum * solid_angle[pixel];
    }
  } else {
    const uint below = 2u * size;
    const uint top_left = params.source_offset + 2u * row * below + 2u * col;
    value = (pyramid[top_left] + pyramid[top_left + 1u]) + (pyramid[top_left + below] + pyramid[top_left + below + 1u]);
  }
  pyramid[params.target_offset + row * size + col] = value;
}
