#version 450
// Hierarchical warping, the sum pyramid (render/hierarchical_warp.h): mode 0 copies the importance
// map into level 0, mode 1 writes one coarse texel per invocation as (a + b) + (c + d) of its
// children, the CPU reference's order, so both pyramids are equal bit for bit.
#include "relight/render/hierarchical_warp_shared.h"

layout(local_size_x = RELIGHT_WARP_LOCAL_SIZE) in;

layout(std430, set = 0, binding = 0) readonly buffer Importance { float importance[]; };
layout(std430, set = 0, binding = 1) buffer Pyramid { float sums[]; };

layout(push_constant) uniform Params { WarpPyramidParams params; };

const float FLOAT_MIN = 1.17549435e-38;

void main() {
  // A 2-D grid of groups where one row would exceed the group-count limit.
  const uint id = gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x + gl_GlobalInvocationID.x;
  const uint side = params.coarse_side;
  if (id >= side * side) return;
  if (params.mode == 0u) {
    const float value = importance[id];
    sums[id] = value < FLOAT_MIN ? 0.0 : value;
    return;
  }
  const uint x = id % side, y = id / side, fine_side = 2u * side;
  const uint top = params.fine_offset + 2u * y * fine_side + 2u * x, bottom = top + fine_side;
  precise float upper = sums[top] + sums[top + 1u];
  precise float lower = sums[bottom] + sums[bottom + 1u];
  precise float total = upper + lower;
  sums[params.coarse_offset + id] = total;
}
