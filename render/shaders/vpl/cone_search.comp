#version 450
// The point-cone search (cone_search.h) on the GPU: work group q answers query q. Each
// invocation keeps the best candidate of its share of the points, then the group reduces
// (least depth, lower index on a tie, as the CPU loop's strict "nearer than the best so far").
#include "relight/render/vpl/cone_search_shared.h"

layout(local_size_x = RELIGHT_CONE_LOCAL_SIZE) in;

layout(std430, set = 0, binding = 0) readonly buffer Points { float points[]; };
layout(std430, set = 0, binding = 1) readonly buffer Queries { float queries[]; };
layout(std430, set = 0, binding = 2) writeonly buffer Hits { uint hits[]; };
layout(push_constant) uniform Push { ConeSearchParams params; };

shared float best_t[RELIGHT_CONE_LOCAL_SIZE];
shared uint best_point[RELIGHT_CONE_LOCAL_SIZE];

vec3 query3(uint q, uint at) {
  const uint base = q * RELIGHT_CONE_QUERY_FLOATS + at;
  return vec3(queries[base], queries[base + 1u], queries[base + 2u]);
}

// The candidate's depth along the ray, or a negative value when the point is no candidate.
float depth(uint i, vec3 origin, vec3 normal, vec3 direction) {
  const uint base = i * RELIGHT_CONE_POINT_FLOATS;
  const vec3 position = vec3(points[base], points[base + 1u], points[base + 2u]);
  const float half_size = points[base + 3u];
  const vec3 point_normal = vec3(points[base + 4u], points[base + 5u], points[base + 6u]);
  const vec3 offset = position - origin;
  const float along = dot(offset, direction);
  if (!(along > 0.0)) return -1.0;
  const float distance = length(offset);
  const float across_squared = max(0.0, distance * distance - along * along);
  const float radius = max(params.tan_half * along, 2.0 * half_size);
  if (across_squared > radius * radius || dot(offset, normal) < params.sin_half * distance) return -1.0;
  const float facing = dot(direction, point_normal);
  if (abs(facing) < 0.2) return along;
  const float plane_t = dot(offset, point_normal) / facing;
  return plane_t > 0.0 ? plane_t : along;
}

void main() {
  const uint q = gl_WorkGroupID.x;
  const uint lane = gl_LocalInvocationID.x;
  const vec3 origin = query3(q, 0u), normal = query3(q, 4u), direction = query3(q, 8u);
  float t_best = queries[q * RELIGHT_CONE_QUERY_FLOATS + 3u];  // max_t
  uint point_best = RELIGHT_CONE_NO_POINT;
  for (uint i = lane; i < params.point_count; i += RELIGHT_CONE_LOCAL_SIZE) {
    const float t = depth(i, origin, normal, direction);
    if (t >= 0.0 && t < t_best) {
      t_best = t;
      point_best = i;
    }
  }
  best_t[lane] = t_best;
  best_point[lane] = point_best;
  barrier();
  for (uint stride = RELIGHT_CONE_LOCAL_SIZE / 2u; stride > 0u; stride /= 2u) {
    if (lane < stride) {
      const float other_t = best_t[lane + stride];
      const uint other_point = best_point[lane + stride];
      if (other_point != RELIGHT_CONE_NO_POINT &&
          (best_point[lane] == RELIGHT_CONE_NO_POINT || other_t < best_t[lane] ||
           (other_t == best_t[lane] && other_point < best_point[lane]))) {
        best_t[lane] = other_t;
        best_point[lane] = other_point;
      }
    }
    barrier();
  }
  if (lane == 0u) {
    hits[2u * q] = floatBitsToUint(best_t[0]);
    hits[2u * q + 1u] = best_point[0];
  }
}
