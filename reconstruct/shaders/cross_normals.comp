#version 450
// Positions from depth (eq. 4.9) and stride-s cross-product normals (eq. 4.4–4.6) in one pass:
// the GPU twin of positions_from_depth + normals_from_positions (definitions in
// normals_from_positions.h). Each invocation re-derives its neighbours' positions from depth
// instead of reading a positions buffer written by another invocation, so one dispatch needs no
// barrier. `precise` forbids fused multiply-adds in the position formula, so positions equal the
// CPU's bit for bit; the normals then differ from the CPU only by sqrt/division rounding.
#include "relight/reconstruct/cross_normals_shared.h"

layout(local_size_x = RELIGHT_CROSS_NORMALS_LOCAL_SIZE, local_size_y = RELIGHT_CROSS_NORMALS_LOCAL_SIZE) in;

layout(std430, set = 0, binding = 0) readonly buffer Depth { float depth[]; };          // row-major metres
layout(std430, set = 0, binding = 1) writeonly buffer Positions { float positions[]; };  // xyz per pixel
layout(std430, set = 0, binding = 2) writeonly buffer Normals { float normals[]; };      // xyz per pixel
layout(push_constant) uniform Push { CrossNormalsParams params; };

// Same test as positions_from_depth on the CPU (finite and positive, comparisons only so that NaN
// fails without relying on a driver's isnan; the CPU bound is 3.4e38f, kept identical here).
bool valid_depth(float z) { return z > 0.0 && z <= 3.4e38; }

// V(r, c) = ((c − cx) z / fx, (r − cy) z / fy, z), (0,0,0) without depth; same operation order as
// the CPU loop: ((c − cx) · inv_fx) · z and ((r − cy) · inv_fy) · z.
vec3 position(int row, int col) {
  const float z = depth[row * int(params.width) + col];
  const float zv = valid_depth(z) ? z : 0.0;
  precise float x = (float(col) - params.cx) * params.inv_fx * zv;
  precise float y_scale = (float(row) - params.cy) * params.inv_fy;
  precise float y = y_scale * zv;
  return vec3(x, y, zv);
}

// A neighbour continues the surface when it has a position and its depth is close to the centre's.
bool continues(vec3 centre, vec3 neighbour) {
  return neighbour.z > 0.0 && abs(neighbour.z - centre.z) <= params.max_jump_rel * centre.z;
}

// Difference along one axis: central (params.centred) if both sides continue, else forward if
// possible, else backward (keeps normals at object borders); false when neither neighbour
// continues the surface.
bool difference(ivec2 forward, bool has_forward, ivec2 backward, bool has_backward, vec3 centre, out vec3 d) {
  const vec3 f = has_forward ? position(forward.y, forward.x) : vec3(0.0);
  const vec3 b = has_backward ? position(backward.y, backward.x) : vec3(0.0);
  const bool forward_ok = has_forward && continues(centre, f);
  const bool backward_ok = has_backward && continues(centre, b);
  if (forward_ok && backward_ok && params.centred != 0u) {
    d = f - b;
    return true;
  }
  if (forward_ok) {
    d = f - centre;
    return true;
  }
  if (backward_ok) {
    d = centre - b;
    return true;
  }
  d = vec3(0.0);
  return false;
}

void store(uint index, vec3 p, vec3 n) {
  positions[3u * index + 0u] = p.x;
  positions[3u * index + 1u] = p.y;
  positions[3u * index + 2u] = p.z;
  normals[3u * index + 0u] = n.x;
  normals[3u * index + 1u] = n.y;
  normals[3u * index + 2u] = n.z;
}

void main() {
  const int col = int(gl_GlobalInvocationID.x);
  const int row = int(gl_GlobalInvocationID.y);
  const int width = int(params.width);
  const int height = int(params.height);
  if (col >= width || row >= height) return;
  const uint index = uint(row * width + col);
  const int s = params.stride;

  const vec3 p = position(row, col);
  if (!(p.z > 0.0)) {
    store(index, p, vec3(0.0));
    return;
  }
  vec3 d_col, d_row;
  if (!difference(ivec2(col + s, row), col + s < width, ivec2(col - s, row), col - s >= 0, p, d_col) ||
      !difference(ivec2(col, row + s), row + s < height, ivec2(col, row - s), row - s >= 0, p, d_row)) {
    store(index, p, vec3(0.0));
    return;
  }
  const vec3 n = cross(d_col, d_row);
  const float len = length(n);
  if (!(len > 0.0)) {
    store(index, p, vec3(0.0));
    return;
  }
  store(index, p, ((dot(n, p) > 0.0 ? -1.0 : 1.0) / len) * n);  // towards the camera (N·V < 0)
}
