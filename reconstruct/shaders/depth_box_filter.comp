#version 450
// 3x3 box filter over a DepthMap that ignores invalid depth; the GPU twin of
// depth_box_filter_cpu.cpp (see depth_box_filter.h for the definition). Same summation order
// (row-major over the window) and one division, so results match the CPU reference bit for bit
// on IEEE-conformant devices.
#include "relight/reconstruct/depth_box_filter_shared.h"

layout(local_size_x = RELIGHT_DEPTH_BOX_FILTER_LOCAL_SIZE, local_size_y = RELIGHT_DEPTH_BOX_FILTER_LOCAL_SIZE) in;

layout(std430, set = 0, binding = 0) readonly buffer Depth { float depth[]; };      // row-major metres
layout(std430, set = 0, binding = 1) writeonly buffer Smoothed { float smoothed[]; };  // same shape
layout(push_constant) uniform Push { DepthBoxFilterParams params; };

// relight::is_valid_depth: finite and positive. Written with comparisons only (NaN fails both),
// so it does not depend on how a driver treats isnan/isinf.
bool is_valid_depth(float metres) { return metres > 0.0 && metres <= 3.40282347e38; }

void main() {
  const int col = int(gl_GlobalInvocationID.x);
  const int row = int(gl_GlobalInvocationID.y);
  const int width = int(params.width);
  const int height = int(params.height);
  if (col >= width || row >= height) return;

  const int index = row * width + col;
  if (!is_valid_depth(depth[index])) {
    smoothed[index] = 0.0;
    return;
  }
  float sum = 0.0;
  int count = 0;
  for (int r = max(row - 1, 0); r <= min(row + 1, height - 1); ++r) {
    for (int c = max(col - 1, 0); c <= min(col + 1, width - 1); ++c) {
      const float d = depth[r * width + c];
      if (is_valid_depth(d)) {
        sum += d;
        ++count;
      }
    }
  }
  smoothed[index] = sum / float(count);  // count >= 1: the centre is valid
}
