#version 450
// Method 2's forward warp (depth_warp_merge.h) as a compute scatter: one invocation per cell of
// the previous depth's vertex grid rasterises the cell's two triangles with warp_depth's rules
// (vertices, rejection, bounding box, inclusive edges, 1/z interpolation) into a z-buffer of
// float bits by atomicMin (positive floats order like their bits). A second pass rasterises
// again and writes each pixel's weight from the triangle whose depth won; where two triangles
// tie exactly, either may write (the CPU keeps the first in its order).
#include "relight/reconstruct/depth_warp_merge_shared.h"

layout(local_size_x = RELIGHT_DEPTH_WARP_LOCAL_SIZE, local_size_y = RELIGHT_DEPTH_WARP_LOCAL_SIZE) in;

layout(std430, set = 0, binding = 0) readonly buffer PreviousDepth { float previous_depth[]; };
layout(std430, set = 0, binding = 1) readonly buffer PreviousWeight { float previous_weight[]; };
layout(std430, set = 0, binding = 2) buffer ZBuffer { uint zbuffer[]; };
layout(std430, set = 0, binding = 3) writeonly buffer Weight { float weight[]; };
layout(push_constant) uniform Push { DepthWarpParams params; };

const uint kFarBits = 0x7f800000u;  // +infinity: nothing drawn
const float kMargin = 1e-3;         // a vertex mapped to 2.0000002 still covers pixel centre 2
const float kInclusive = -1e-4;     // pixel centres on a shared edge belong to both triangles

// (u, v, z, weight); z <= 0: no vertex (no depth, or behind the current camera).
vec4 warped_vertex(int col, int row) {
  const uint i = uint(row) * params.width + uint(col);
  const float z = previous_depth[i];
  if (!(z > 0.0 && z <= 3.4e38)) return vec4(0.0);
  const float x = (float(col) - params.cx) / params.fx * z;
  const float y = (float(row) - params.cy) / params.fy * z;
  const float m[12] = params.current_from_prev;
  const float px = m[0] * x + m[1] * y + m[2] * z + m[3];
  const float py = m[4] * x + m[5] * y + m[6] * z + m[7];
  const float pz = m[8] * x + m[9] * y + m[10] * z + m[11];
  if (!(pz > 0.0)) return vec4(0.0);
  return vec4(params.fx * px / pz + params.cx, params.fy * py / pz + params.cy, pz,
              params.has_weight != 0u ? previous_weight[i] : 1.0);
}

float edge_function(vec2 a, vec2 b, vec2 p) { return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x); }

void rasterise(vec4 a, vec4 b, vec4 c) {
  if (!(a.z > 0.0 && b.z > 0.0 && c.z > 0.0)) return;
  // The bounding box of pixel centres, clamped to the image before any conversion to int.
  const float x0 = max(0.0, ceil(min(min(a.x, b.x), c.x) - kMargin));
  const float x1 = min(float(params.width - 1u), floor(max(max(a.x, b.x), c.x) + kMargin));
  const float y0 = max(0.0, ceil(min(min(a.y, b.y), c.y) - kMargin));
  const float y1 = min(float(params.height - 1u), floor(max(max(a.y, b.y), c.y) + kMargin));
  if (!(x0 <= x1 && y0 <= y1)) return;
  const float z_min = min(min(a.z, b.z), c.z), z_max = max(max(a.z, b.z), c.z);
  if (z_max - z_min > params.max_edge_m + params.max_edge_rel * z_min) return;  // across a discontinuity
  const float area = edge_function(a.xy, b.xy, c.xy);
  if (abs(area) < 1e-8) return;
  const float inv_area = 1.0 / area;
  const float w = min(min(a.w, b.w), c.w);
  for (int y = int(y0); y <= int(y1); ++y) {
    for (int x = int(x0); x <= int(x1); ++x) {
      const vec2 p = vec2(float(x), float(y));
      const float w0 = edge_function(b.xy, c.xy, p) * inv_area;
      const float w1 = edge_function(c.xy, a.xy, p) * inv_area;
      const float w2 = 1.0 - w0 - w1;
      if (w0 < kInclusive || w1 < kInclusive || w2 < kInclusive) continue;
      const float z = 1.0 / (w0 / a.z + w1 / b.z + w2 / c.z);  // 1/z is affine in screen space
      if (!(z > 0.0)) continue;
      const uint index = uint(y) * params.width + uint(x);
      if (params.mode == RELIGHT_DEPTH_WARP_DEPTH) {
        atomicMin(zbuffer[index], floatBitsToUint(z));
      } else if (zbuffer[index] == floatBitsToUint(z)) {
        weight[index] = w;
      }
    }
  }
}

void main() {
  const int col = int(gl_GlobalInvocationID.x), row = int(gl_GlobalInvocationID.y);
  if (params.mode == RELIGHT_DEPTH_WARP_CLEAR) {
    if (col < int(params.width) && row < int(params.height)) zbuffer[uint(row) * params.width + uint(col)] = kFarBits;
    return;
  }
  if (col + 1 >= int(params.width) || row + 1 >= int(params.height)) return;  // cells: one fewer per side
  const vec4 top_left = warped_vertex(col, row), top_right = warped_vertex(col + 1, row);
  const vec4 bottom_left = warped_vertex(col, row + 1), bottom_right = warped_vertex(col + 1, row + 1);
  rasterise(top_left, top_right, bottom_left);      // the cell's upper-left triangle, as warp_depth
  rasterise(top_right, bottom_right, bottom_left);  // and its lower-right one
}
