#version 450
// Test shader: evaluates the GLSL twin of the Phong model (core/shaders/phong.glsl) for a table of
// cases, so tests/core/vk/phong_twin_test.cpp can compare it with core/phong.h.
// Case i: normal (w: n), wi, wo, k_d (w: k_s); out[i] = (f, phong_specular of the same pair).
#include "phong.glsl"

layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) readonly buffer Cases { vec4 cases[]; };
layout(std430, set = 0, binding = 1) writeonly buffer Results { vec4 results[]; };
layout(push_constant) uniform Params { uint count; } params;

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= params.count) return;
  const vec4 normal_n = cases[4u * i], wi = cases[4u * i + 1u], wo = cases[4u * i + 2u], kd_ks = cases[4u * i + 3u];
  const vec3 f = phong_brdf(kd_ks.xyz, kd_ks.w, normal_n.w, normal_n.xyz, wi.xyz, wo.xyz);
  const float specular = phong_specular(kd_ks.w, normal_n.w, dot(phong_reflect(wi.xyz, normal_n.xyz), wo.xyz));
  results[i] = vec4(f, specular);
}
