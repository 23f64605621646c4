#version 450
// Hierarchical warping, the sum pyramid (render/hierarchical_warp.h). One dispatch writes up to
// three levels: each invocation reads a 2^n x 2^n block of the level below (n = level_count) and
// sums it down level by level in registers, so a 512^2 map takes three dispatches instead of
// ten and no invocation waits at a barrier. Every parent is (a + b) + (c + d) of its children,
// the CPU reference's order, so both pyramids are equal bit for bit. Mode 0 reads the importance
// map itself (flushing subnormal values to 0) and also writes it as level 0; with no level to
// write (a 1x1 map) it only copies.
#include "relight/render/vpl/hierarchical_warp_shared.h"

layout(local_size_x = RELIGHT_WARP_PYRAMID_GROUP, local_size_y = RELIGHT_WARP_PYRAMID_GROUP) in;

layout(std430, set = 0, binding = 0) readonly buffer Importance { float importance[]; };
layout(std430, set = 0, binding = 1) buffer Pyramid { float sums[]; };

layout(push_constant) uniform Params { WarpPyramidParams params; };

const float FLOAT_MIN = 1.17549435e-38;
const uint MAX_SPAN = 1u << RELIGHT_WARP_LEVELS_PER_DISPATCH;

float fine(uint x, uint y) {
  const uint index = y * params.fine_side + x;
  if (params.mode == 0u) {
    const float value = importance[index];
    const float flushed = value < FLOAT_MIN ? 0.0 : value;
    sums[index] = flushed;
    return flushed;
  }
  return sums[params.fine_offset + index];
}

void main() {
  if (params.level_count == 0u) {
    if (gl_GlobalInvocationID.xy == uvec2(0u)) fine(0u, 0u);
    return;
  }
  const uint span = 1u << params.level_count;
  const uvec2 block = gl_GlobalInvocationID.xy;
  if (block.x >= params.fine_side / span || block.y >= params.fine_side / span) return;
  float values[MAX_SPAN * MAX_SPAN];
  for (uint y = 0u; y < span; ++y)
    for (uint x = 0u; x < span; ++x) values[y * span + x] = fine(block.x * span + x, block.y * span + y);
  uint n = span, side = params.fine_side;
  for (uint level = 0u; level < params.level_count; ++level) {
    // In place: texel (x, y) of the coarser level overwrites an entry its successors no longer read.
    const uint half_n = n / 2u;
    side /= 2u;
    for (uint y = 0u; y < half_n; ++y)
      for (uint x = 0u; x < half_n; ++x) {
        const uint i = 2u * y * n + 2u * x;
        precise float top = values[i] + values[i + 1u];
        precise float bottom = values[i + n] + values[i + n + 1u];
        precise float total = top + bottom;
        values[y * half_n + x] = total;
        sums[params.offsets[level] + (block.y * half_n + y) * side + block.x * half_n + x] = total;
      }
    n = half_n;
  }
}
