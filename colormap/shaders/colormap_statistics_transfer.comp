#version 450
// Pass 2 of the statistics-based mapping: delta_L = tau_st(L_rv) - tau_st(L_r) per pixel
// (eq. 4.28 with tau_st of eq. 4.30); exactly 0 where L_rv == L_r, as on the CPU.
#include "relight/colormap/colormap_shared.h"
#include "colormap_lab.glsl"

layout(local_size_x = RELIGHT_COLORMAP_STATS_GROUP) in;

layout(std430, set = 0, binding = 0) readonly buffer Real { float real[]; };
layout(std430, set = 0, binding = 1) readonly buffer RealVirtual { float real_virtual[]; };
layout(std430, set = 0, binding = 2) writeonly buffer Delta { float delta[]; };
layout(push_constant) uniform Push { ColormapTransferParams params; };

vec3 tau_st(vec3 radiance) {
  const vec3 lab = linear_srgb_to_lab(tone_map(radiance, params.tone_map));
  const vec3 scale = vec3(params.scale[0], params.scale[1], params.scale[2]);
  const vec3 offset = vec3(params.offset[0], params.offset[1], params.offset[2]);
  return lab_to_linear_srgb(scale * lab + offset);
}

void main() {
  const uint pixel = gl_GlobalInvocationID.x;
  if (pixel >= params.pixels) return;
  const vec3 r = vec3(real[3 * pixel], real[3 * pixel + 1], real[3 * pixel + 2]);
  const vec3 rv = vec3(real_virtual[3 * pixel], real_virtual[3 * pixel + 1], real_virtual[3 * pixel + 2]);
  const vec3 d = all(equal(r, rv)) ? vec3(0.0) : tau_st(rv) - tau_st(r);
  delta[3 * pixel] = d.x;
  delta[3 * pixel + 1] = d.y;
  delta[3 * pixel + 2] = d.z;
}
