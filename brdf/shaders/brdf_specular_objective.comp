#version 450
// The specular objective F (specular_fit.h, eq. 4.15) for a batch of parameter candidates
// (specular_objective_vk.h): invocation x evaluates sample x under candidate y with the model of
// shading.h (both the diffuse and the Phong term of core/shaders/phong.glsl, the same expression as
// model_radiance in src/specular_model.h, here in float), and each work group adds its samples' squared residuals
// into one partial sum per candidate, which the host adds up in double.
#include "phong.glsl"
#include "relight/brdf/specular_shared.h"

layout(local_size_x = RELIGHT_SPECULAR_GROUP) in;

layout(std430, set = 0, binding = 0) readonly buffer Samples { vec4 samples[]; };
layout(std430, set = 0, binding = 1) readonly buffer Lights { vec4 lights[]; };
layout(std430, set = 0, binding = 2) readonly buffer Candidates { vec4 candidates[]; };
layout(std430, set = 0, binding = 3) writeonly buffer Partials { float partials[]; };  // candidate-major
layout(push_constant) uniform Push { SpecularObjectiveParams params; };

shared float sums[RELIGHT_SPECULAR_GROUP];

float squared_residual(uint sample_index, uint candidate) {
  const uint s = sample_index * RELIGHT_SPECULAR_SAMPLE_VEC4S;
  const vec3 radiance = samples[s].xyz, p = samples[s + 1].xyz, normal = samples[s + 2].xyz;
  const uint c = candidate * RELIGHT_SPECULAR_CANDIDATE_VEC4S;
  const float ks = candidates[c].x, n = candidates[c].y;
  const vec3 kd = params.kd.xyz;
  vec3 model = kd * params.ambient.xyz;
  const vec3 v = -p / sqrt(dot(p, p));
  const float lobe_scale = ks * phong_lobe_normalisation(n);
  for (uint l = 0u; l < params.lights; ++l) {
    vec3 to_light = lights[RELIGHT_SPECULAR_LIGHT_VEC4S * l].xyz;
    const bool point = lights[RELIGHT_SPECULAR_LIGHT_VEC4S * l].w > 0.5;
    if (l < params.moving) to_light += candidates[c + 1u + l].xyz;
    float scale = 1.0;  // irradiance factor per unit power at normal incidence
    if (point) {
      to_light -= p;
      const float d2 = dot(to_light, to_light);
      to_light /= sqrt(d2);
      scale = 1.0 / d2;
    } else {
      to_light /= sqrt(dot(to_light, to_light));
    }
    const float cosine = dot(normal, to_light);
    if (!(cosine > 0.0)) continue;
    const float rv = dot(2.0 * cosine * normal - to_light, v);
    const float lobe = phong_lobe(n, rv);
    const vec3 power = lights[RELIGHT_SPECULAR_LIGHT_VEC4S * l + 1u].xyz;
    model += (scale * cosine) * power * (kd * kPhongInvPi + lobe_scale * lobe);
  }
  const vec3 r = radiance - model;
  return dot(r, r);
}

void main() {
  const uint local = gl_LocalInvocationID.x;
  const uint sample_index = gl_GlobalInvocationID.x;
  const uint candidate = gl_WorkGroupID.y;
  sums[local] = sample_index < params.samples ? squared_residual(sample_index, candidate) : 0.0;
  barrier();
  for (uint stride = RELIGHT_SPECULAR_GROUP / 2u; stride > 0u; stride /= 2u) {
    if (local < stride) sums[local] += sums[local + stride];
    barrier();
  }
  if (local == 0u) partials[candidate * params.groups + gl_WorkGroupID.x] = sums[0];
}
