#version 450
// Hierarchical warping of one Hammersley point per invocation down the importance pyramid, and
// the VPL it becomes (importance_sampling.h, steps 2-3); the GPU twin of warp_point and
// sample_importance in importance_sampling_cpu.cpp, operation for operation.
#include "relight/lights/importance_shared.h"

layout(local_size_x = RELIGHT_IMPORTANCE_WARP_LOCAL_SIZE) in;

layout(std430, set = 0, binding = 0) readonly buffer Pyramid { float pyramid[]; };
layout(std430, set = 0, binding = 1) readonly buffer Radiance { float radiance[]; };
layout(std430, set = 0, binding = 2) readonly buffer SolidAngle { float solid_angle[]; };
layout(std430, set = 0, binding = 3) writeonly buffer Samples { ImportanceSampleOut samples[]; };
layout(push_constant) uniform Push { ImportanceWarpParams params; };

const float kOneMinusEps = RELIGHT_IMPORTANCE_ONE_MINUS_EPS;
const float kPi = 3.14159265358979;

float non_negative(float value) { return value > 0.0 ? value : 0.0; }

uint level_offset(uint level) {
  uint offset = 0u;
  for (uint k = 0u; k < level; ++k) {
    const uint edge = 1u << (params.levels - k);
    offset += edge * edge;
  }
  return offset;
}

float at(uint level, uint row, uint col) {
  return pyramid[level_offset(level) + row * (1u << (params.levels - level)) + col];
}

// Returns true for the second half; rescales `coordinate` into the chosen half.
bool warp_binary(float first, float second, inout float coordinate) {
  precise float scaled = coordinate * (first + second);
  if (scaled < first || !(second > 0.0)) {
    coordinate = min(scaled / first, kOneMinusEps);
    return false;
  }
  precise float rest = scaled - first;
  coordinate = min(rest / second, kOneMinusEps);
  return true;
}

vec3 probe_direction(float u, float v) {
  vec3 local;
  if (params.projection == 0u) {
    const float du = u - params.cx;
    const float dv = v - params.cy;
    const float r = sqrt(du * du + dv * dv);
    const float theta = min(r / params.focal, params.max_theta);
    if (r < 1e-12) {
      local = vec3(0.0, 0.0, 1.0);
    } else {
      const float s = sin(theta) / r;
      local = vec3(du * s, dv * s, cos(theta));
    }
  } else {
    const float theta = kPi * (v + 0.5) / float(params.height);
    const float phi = 2.0 * kPi * (u + 0.5) / float(params.width);
    local = vec3(sin(theta) * cos(phi), sin(theta) * sin(phi), cos(theta));
  }
  const float m[9] = params.probe_to_world;
  return normalize(vec3(m[0] * local.x + m[1] * local.y + m[2] * local.z,
                        m[3] * local.x + m[4] * local.y + m[5] * local.z,
                        m[6] * local.x + m[7] * local.y + m[8] * local.z));
}

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= params.samples) return;

  // Rotated Hammersley point, as hammersley_point().
  const float radical = float(bitfieldReverse(i) >> 8) * (1.0 / 16777216.0);
  precise float u = (float(i) + 0.5) * params.inverse_samples + params.offset_u;
  precise float v = radical + params.offset_v;
  u = min(u - floor(u), kOneMinusEps);
  v = min(v - floor(v), kOneMinusEps);

  uint col = 0u, row = 0u;
  for (uint level = params.levels; level >= 1u; --level) {
    const uint below = level - 1u;
    const float top_left = at(below, 2u * row, 2u * col), top_right = at(below, 2u * row, 2u * col + 1u);
    const float bottom_left = at(below, 2u * row + 1u, 2u * col);
    const float bottom_right = at(below, 2u * row + 1u, 2u * col + 1u);
    precise float left = top_left + bottom_left;
    precise float right = top_right + bottom_right;
    const bool go_right = warp_binary(left, right, u);
    col = 2u * col + (go_right ? 1u : 0u);
    const bool bottom = go_right ? warp_binary(top_right, bottom_right, v) : warp_binary(top_left, bottom_left, v);
    row = 2u * row + (bottom ? 1u : 0u);
  }

  const uint pixel = row * params.width + col;
  const float total = pyramid[level_offset(params.levels)];
  const float scale = solid_angle[pixel] * total / (at(0u, row, col) * float(params.samples));
  ImportanceSampleOut result;
  const vec3 d = probe_direction(float(col) + u - 0.5, float(row) + v - 0.5);
  result.direction[0] = d.x;
  result.direction[1] = d.y;
  result.direction[2] = d.z;
  result.pixel = pixel;
  result.power[0] = scale * non_negative(radiance[3u * pixel]);
  result.power[1] = scale * non_negative(radiance[3u * pixel + 1u]);
  result.power[2] = scale * non_negative(radiance[3u * pixel + 2u]);
  result.u = u;
  result.v = v;
  result.pad0 = 0.0;
  result.pad1 = 0.0;
  result.pad2 = 0.0;
  samples[i] = result;
}
