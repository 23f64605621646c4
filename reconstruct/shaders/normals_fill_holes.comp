#version 450
// Method 1's hole filling, the GPU twin of fill_holes in normals_raw_depth_cpu.cpp: a pixel with
// a position but no normal takes the normalised sum of its 4-neighbours' normals (missing ones
// are zero). Reads `blended`, writes `normals`, so neighbours are read before any fill, as on
// the CPU (which collects the fills before applying them).
#include "relight/reconstruct/normals_blend_shared.h"

layout(local_size_x = RELIGHT_NORMALS_BLEND_LOCAL_SIZE, local_size_y = RELIGHT_NORMALS_BLEND_LOCAL_SIZE) in;

layout(std430, set = 0, binding = 0) readonly buffer Positions { float positions[]; };
layout(std430, set = 0, binding = 1) readonly buffer Blended { float blended[]; };
layout(std430, set = 0, binding = 2) writeonly buffer Normals { float normals[]; };
layout(push_constant) uniform Push { NormalsFillParams params; };

vec3 at(int row, int col) {
  const uint i = uint(row) * params.width + uint(col);
  return vec3(blended[3u * i], blended[3u * i + 1u], blended[3u * i + 2u]);
}

void main() {
  const int col = int(gl_GlobalInvocationID.x);
  const int row = int(gl_GlobalInvocationID.y);
  const int width = int(params.width), height = int(params.height);
  if (col >= width || row >= height) return;
  const uint i = uint(row) * params.width + uint(col);
  vec3 n = at(row, col);
  if (positions[3u * i + 2u] > 0.0 && !(dot(n, n) > 0.0)) {
    vec3 sum = vec3(0.0);  // same order as the CPU: up, down, left, right
    if (row > 0) sum += at(row - 1, col);
    if (row + 1 < height) sum += at(row + 1, col);
    if (col > 0) sum += at(row, col - 1);
    if (col + 1 < width) sum += at(row, col + 1);
    const float len = length(sum);
    if (len > 0.0) n = sum / len;
  }
  normals[3u * i] = n.x;
  normals[3u * i + 1u] = n.y;
  normals[3u * i + 2u] = n.z;
}
