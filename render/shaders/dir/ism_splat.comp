#version 450
// Imperfect shadow maps, splat pass (render/ism.h): one invocation per (point slot, VPL, layer)
// maps the point's normal-aligned square into the VPL's paraboloid tile and keeps the minimum
// distance per texel (atomicMin on the float's bits: non-negative floats order like uints).
#include "dir_common.glsl"

layout(local_size_x = 64) in;

struct Point {
  vec4 position_half_size;
  vec4 normal;
};

layout(std430, set = 0, binding = 0) readonly buffer Points { Point points[]; };  // real pool, then virtual
layout(std430, set = 0, binding = 1) readonly buffer Vpls { Vpl vpls[]; };
layout(std430, set = 0, binding = 2) buffer Atlas { uint atlas[]; };

layout(push_constant) uniform Params {
  int tile;
  uint points_per_vpl;
  uint vpl_count;
  uint real_pool;
  uint virtual_pool;
  uint pad0, pad1, pad2;
  vec4 virtual_bounds;  // IsmPointPools::virtual_bounds
  vec4 scene_bounds;    // IsmPointPools::scene_bounds
} params;

const int MAX_SPLAT = 16;  // kMaxSplat

float edge_function(vec2 a, vec2 b, vec2 p) { return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x); }

void main() {
  const uint slot = gl_GlobalInvocationID.x, vpl_index = gl_GlobalInvocationID.y, layer = gl_GlobalInvocationID.z;
  if (slot >= params.points_per_vpl || vpl_index >= params.vpl_count) return;
  const uint pool = layer == 0u ? params.real_pool : params.virtual_pool;
  if (pool == 0u) return;
  const Point point = points[(layer == 0u ? 0u : params.real_pool) + ism_point_index(vpl_index, slot, pool)];
  const Vpl vpl = vpls[vpl_index];
  const Projection projection =
      layer == 0u ? real_tile(vpl, params.scene_bounds) : virtual_tile(vpl, params.virtual_bounds, params.scene_bounds);
  float distance;
  const vec3 centre_dir = projection_local(projection, point.position_half_size.xyz, distance);
  vec2 centre;
  if (!(distance > 1e-4) || centre_dir.z <= 0.0 || !projection_texel(projection, centre_dir, params.tile, centre)) return;
  const int tile = params.tile;
  vec3 tp, bp;
  orthonormal_basis(point.normal.xyz, tp, bp);
  const float h = point.position_half_size.w;
  const vec2 signs[4] = vec2[4](vec2(1, 1), vec2(-1, 1), vec2(-1, -1), vec2(1, -1));
  vec2 corners[4];
  vec2 low = centre, high = centre;
  for (int k = 0; k < 4; ++k) {
    float corner_distance;
    const vec3 dir = projection_local(projection, point.position_half_size.xyz + h * (signs[k].x * tp + signs[k].y * bp),
                                      corner_distance);
    if (!(corner_distance > 1e-4) || dir.z <= 1e-3) {
      corners[k] = centre;
    } else {
      vec2 c;
      projection_texel(projection, dir, tile, c);
      corners[k] = c;
    }
    low = min(low, corners[k]);
    high = max(high, corners[k]);
  }
  const uint base = (layer * params.vpl_count + vpl_index) * uint(tile * tile);
  const uint bits = floatBitsToUint(distance);
  const int cx = clamp(int(floor(centre.x)), 0, tile - 1), cy = clamp(int(floor(centre.y)), 0, tile - 1);
  const int x0 = max(max(0, int(floor(low.x))), cx - MAX_SPLAT / 2);
  const int y0 = max(max(0, int(floor(low.y))), cy - MAX_SPLAT / 2);
  const int x1 = min(min(tile - 1, int(floor(high.x))), x0 + MAX_SPLAT - 1);
  const int y1 = min(min(tile - 1, int(floor(high.y))), y0 + MAX_SPLAT - 1);
  // Per texel: the distance along its direction to the point's tangent plane (ism.cpp: splat()).
  const vec3 pn = point.normal.xyz;
  const vec3 plane_normal_local = vec3(dot(pn, projection.t), dot(pn, projection.b), dot(pn, projection.n));
  const float plane_offset = dot(point.position_half_size.xyz - projection.origin, pn);
  const float near = distance - 2.0 * h, far = distance + 2.0 * h;
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) {
      const vec2 p = vec2(x, y) + 0.5;
      bool positive = true, negative = true;
      for (int k = 0; k < 4; ++k) {
        const float e = edge_function(corners[k], corners[(k + 1) % 4], p);
        positive = positive && e >= 0.0;
        negative = negative && e <= 0.0;
      }
      if (positive || negative) {
        const float facing = dot(projection_direction(projection, p, tile), plane_normal_local);
        const float along = abs(facing) > 1e-3 ? clamp(plane_offset / facing, near, far) : distance;
        atomicMin(atlas[base + uint(y * tile + x)], floatBitsToUint(max(along, 0.0)));
      }
    }
  atomicMin(atlas[base + uint(cy * tile + cx)], bits);
}
