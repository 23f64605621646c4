#version 450
// Hierarchical warping, the descent (render/hierarchical_warp.h): one invocation per point walks
// the sum pyramid from the total down to level 0 with the CPU reference's operations (pick_first
// in hierarchical_warp.cpp), `precise` so that no multiply-add is fused, and writes the texel and
// its probability importance / total.
#include "relight/render/vpl/hierarchical_warp_shared.h"

layout(local_size_x = RELIGHT_WARP_LOCAL_SIZE) in;

layout(std430, set = 0, binding = 0) readonly buffer Pyramid { float sums[]; };
layout(std430, set = 0, binding = 1) readonly buffer Points { vec2 points[]; };
layout(std430, set = 0, binding = 2) writeonly buffer Samples { uint samples[]; };

layout(push_constant) uniform Params { WarpDescendParams params; };

const float BELOW_ONE = 0.99999994;  // the largest float below 1 (0x3f7fffff)

bool pick_first(float first, float second, inout float x) {
  precise float mass = first + second;
  precise float t = x * mass;
  const bool take_first = second == 0.0 || (first > 0.0 && t < first);
  precise float rest = t - first;
  precise float rescaled = take_first ? t / first : rest / second;
  x = min(rescaled, BELOW_ONE);
  return take_first;
}

void main() {
  const uint id = gl_GlobalInvocationID.x;
  if (id >= params.count) return;
  uint offsets[RELIGHT_WARP_MAX_LEVELS];
  uint offset = 0u;
  for (uint level = 0u; level < params.levels; ++level) {
    offsets[level] = offset;
    const uint side = params.size >> level;
    offset += side * side;
  }
  const float total = sums[offsets[params.levels - 1u]];
  if (!(total > 0.0)) {
    samples[3u * id] = RELIGHT_WARP_NO_TEXEL;
    samples[3u * id + 1u] = RELIGHT_WARP_NO_TEXEL;
    samples[3u * id + 2u] = 0u;
    return;
  }
  float u = min(max(points[id].x, 0.0), BELOW_ONE);
  float v = min(max(points[id].y, 0.0), BELOW_ONE);
  uint x = 0u, y = 0u;
  for (int child = int(params.levels) - 2; child >= 0; --child) {
    const uint side = params.size >> uint(child);
    const uint base = offsets[child];
    const uint cx = 2u * x, cy = 2u * y;
    const float a = sums[base + cy * side + cx], b = sums[base + cy * side + cx + 1u];
    const float c = sums[base + (cy + 1u) * side + cx], d = sums[base + (cy + 1u) * side + cx + 1u];
    precise float left_mass = a + c;
    precise float right_mass = b + d;
    const bool left = pick_first(left_mass, right_mass, u);
    x = left ? cx : cx + 1u;
    y = pick_first(left ? a : b, left ? c : d, v) ? cy : cy + 1u;
  }
  precise float probability = sums[y * params.size + x] / total;
  samples[3u * id] = x;
  samples[3u * id + 1u] = y;
  samples[3u * id + 2u] = floatBitsToUint(probability);
}
