#version 450
// Pass 1 of the statistics-based mapping (statistics_transfer_vk.h): the masked Lab sums of
// f(TM(L_r)) and f(L_cam) per work group. Same valid-pixel rule as is_statistics_pixel().
#include "relight/colormap/colormap_shared.h"
#include "colormap_lab.glsl"

layout(local_size_x = RELIGHT_COLORMAP_STATS_GROUP) in;

layout(std430, set = 0, binding = 0) readonly buffer Real { float real[]; };                // Float3 per pixel
layout(std430, set = 0, binding = 1) readonly buffer RealVirtual { float real_virtual[]; };  // Float3 per pixel
layout(std430, set = 0, binding = 2) readonly buffer Camera { uint camera_words[]; };        // Rgb8, packed
layout(std430, set = 0, binding = 3) writeonly buffer Sums { float sums[]; };  // one row per work group
layout(push_constant) uniform Push { ColormapStatisticsParams params; };

const uint kValues = 13;
shared float partial[kValues][RELIGHT_COLORMAP_STATS_GROUP];

uint camera_byte(uint index) { return (camera_words[index >> 2] >> ((index & 3u) * 8u)) & 0xffu; }

// Finite without isnan/isinf, whose treatment varies between drivers.
bool is_finite(float v) { return abs(v) <= 3.40282347e38; }

void main() {
  const uint pixel = gl_GlobalInvocationID.x;
  const uint local = gl_LocalInvocationID.x;
  float values[kValues];
  for (uint k = 0; k < kValues; ++k) values[k] = 0.0;

  if (pixel < params.pixels) {
    const vec3 r = vec3(real[3 * pixel], real[3 * pixel + 1], real[3 * pixel + 2]);
    const vec3 rv = vec3(real_virtual[3 * pixel], real_virtual[3 * pixel + 1], real_virtual[3 * pixel + 2]);
    const uvec3 c = uvec3(camera_byte(3 * pixel), camera_byte(3 * pixel + 1), camera_byte(3 * pixel + 2));
    const vec3 mapped = tone_map(r, params.tone_map);
    const bool valid = is_finite(r.x) && is_finite(r.y) && is_finite(r.z) && all(equal(r, rv)) &&
                       any(notEqual(c, uvec3(0))) && any(greaterThan(mapped, vec3(0.0)));
    if (valid) {
      const vec3 source = linear_srgb_to_lab(mapped);
      const vec3 camera_linear = vec3(srgb_to_linear(float(c.x) / 255.0), srgb_to_linear(float(c.y) / 255.0),
                                      srgb_to_linear(float(c.z) / 255.0));
      const vec3 target = linear_srgb_to_lab(camera_linear);
      values[0] = 1.0;
      for (int k = 0; k < 3; ++k) {
        values[1 + k] = source[k];
        values[4 + k] = source[k] * source[k];
        values[7 + k] = target[k];
        values[10 + k] = target[k] * target[k];
      }
    }
  }
  for (uint k = 0; k < kValues; ++k) partial[k][local] = values[k];
  barrier();
  for (uint stride = RELIGHT_COLORMAP_STATS_GROUP / 2; stride > 0; stride /= 2) {
    if (local < stride) {
      for (uint k = 0; k < kValues; ++k) partial[k][local] += partial[k][local + stride];
    }
    barrier();
  }
  if (local == 0) {
    const uint row = gl_WorkGroupID.x * RELIGHT_COLORMAP_SUMS_STRIDE;
    for (uint k = 0; k < kValues; ++k) sums[row + k] = partial[k][0];
    for (uint k = kValues; k < RELIGHT_COLORMAP_SUMS_STRIDE; ++k) sums[row + k] = 0.0;
  }
}
