#version 450
// Method 1's pass 2 temporal blend (eq. 4.7–4.8), the GPU twin of blend_with_history in
// normals_raw_depth_cpu.cpp (definition in normals_raw_depth.h). The pass-1 pyramid is built on
// the CPU and uploaded: level l's normals follow level l−1's in one buffer, row-major.
#include "relight/reconstruct/normals_blend_shared.h"

layout(local_size_x = RELIGHT_NORMALS_BLEND_LOCAL_SIZE, local_size_y = RELIGHT_NORMALS_BLEND_LOCAL_SIZE) in;

layout(std430, set = 0, binding = 0) readonly buffer Positions { float positions[]; };        // this frame, xyz
layout(std430, set = 0, binding = 1) readonly buffer Fresh { float fresh[]; };                // stride-s normals, xyz
layout(std430, set = 0, binding = 2) readonly buffer PrevPositions { float prev_positions[]; };  // previous frame, xyz
layout(std430, set = 0, binding = 3) readonly buffer Pyramid { float pyramid[]; };            // A_l, xyz
layout(std430, set = 0, binding = 4) readonly buffer Curvature { float curvature[]; };        // level 0 only
layout(std430, set = 0, binding = 5) writeonly buffer Blended { float blended[]; };           // xyz
layout(push_constant) uniform Push { NormalsBlendParams params; };

vec3 load3_fresh(uint i) { return vec3(fresh[3u * i], fresh[3u * i + 1u], fresh[3u * i + 2u]); }
vec3 load3_pyramid(uint i) { return vec3(pyramid[3u * i], pyramid[3u * i + 1u], pyramid[3u * i + 2u]); }

// relight::is_valid_normal without isnan/isinf (the buffers hold only finite values or zeros).
bool valid_normal(vec3 n) { return dot(n, n) > 0.0; }

// std::lround: halves away from zero.
int round_half_away(float x) { return x >= 0.0 ? int(floor(x + 0.5)) : -int(floor(-x + 0.5)); }

// Texel (row, col) of pyramid level `level`; level sizes halve (rounding up) from half resolution.
vec3 level_texel(int level, int row, int col) {
  uint width = (params.width + 1u) / 2u, height = (params.height + 1u) / 2u, offset = 0u;
  for (int l = 0; l < level; ++l) {
    offset += width * height;
    width = (width + 1u) / 2u;
    height = (height + 1u) / 2u;
  }
  return load3_pyramid(offset + uint(row) * width + uint(col));
}

vec3 blend(vec3 n, vec3 p) {
  const float m[12] = params.prev_from_current;
  const vec3 q = vec3(m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3], m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7],
                      m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]);
  if (!(q.z > 0.0)) return n;
  const float u = params.fx * q.x / q.z + params.cx;
  const float v = params.fy * q.y / q.z + params.cy;
  if (!(abs(u) < 1e8 && abs(v) < 1e8)) return n;  // int conversion would overflow: off the image anyway
  const int col = round_half_away(u), row = round_half_away(v);
  if (col < 0 || row < 0 || col >= int(params.width) || row >= int(params.height)) return n;
  const float previous_z = prev_positions[3u * (uint(row) * params.width + uint(col)) + 2u];
  if (!(previous_z > 0.0) || abs(previous_z - q.z) > params.disocclusion_m) return n;

  const int max_level = int(params.levels) - 1;
  const uint half_width = (params.width + 1u) / 2u;
  const float curv = curvature[uint(row / 2) * half_width + uint(col / 2)];
  const int level = clamp(round_half_away(curv * float(max_level)), 0, max_level);
  vec3 history = level_texel(level, row >> (level + 1), col >> (level + 1));
  if (!valid_normal(history)) history = level_texel(0, row / 2, col / 2);
  if (!valid_normal(history)) return n;
  const float r[9] = params.current_from_prev;
  history = vec3(r[0] * history.x + r[1] * history.y + r[2] * history.z,
                 r[3] * history.x + r[4] * history.y + r[5] * history.z,
                 r[6] * history.x + r[7] * history.y + r[8] * history.z);

  const float c_n = abs(dot(history, n));                       // eq. 4.7
  const float c = params.blend_base * c_n + (1.0 - c_n);        // eq. 4.8
  const vec3 mixed = c * history + (1.0 - c) * n;
  const float len = length(mixed);
  return len > 0.0 ? mixed / len : n;
}

void main() {
  const int col = int(gl_GlobalInvocationID.x);
  const int row = int(gl_GlobalInvocationID.y);
  if (col >= int(params.width) || row >= int(params.height)) return;
  const uint i = uint(row) * params.width + uint(col);
  vec3 n = load3_fresh(i);
  if (valid_normal(n)) n = blend(n, vec3(positions[3u * i], positions[3u * i + 1u], positions[3u * i + 2u]));
  blended[3u * i] = n.x;
  blended[3u * i + 1u] = n.y;
  blended[3u * i + 2u] = n.z;
}
