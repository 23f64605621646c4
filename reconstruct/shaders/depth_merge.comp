#version 450
// Method 2's merge (merge_depth in depth_warp_merge.h): the new raw depth against the warped
// history, per pixel. The z-buffer of depth_warp.comp is read as float bits (+infinity: not
// covered). σ_z is evaluated in float here (double on the CPU).
#include "relight/reconstruct/depth_warp_merge_shared.h"

layout(local_size_x = RELIGHT_DEPTH_WARP_LOCAL_SIZE, local_size_y = RELIGHT_DEPTH_WARP_LOCAL_SIZE) in;

layout(std430, set = 0, binding = 0) readonly buffer Depth { float depth[]; };
layout(std430, set = 0, binding = 1) readonly buffer ZBuffer { uint zbuffer[]; };
layout(std430, set = 0, binding = 2) readonly buffer WarpedWeight { float warped_weight[]; };
layout(std430, set = 0, binding = 3) writeonly buffer Merged { float merged[]; };
layout(std430, set = 0, binding = 4) writeonly buffer MergedWeight { float merged_weight[]; };
layout(push_constant) uniform Push { DepthMergeParams params; };

void main() {
  const uint col = gl_GlobalInvocationID.x, row = gl_GlobalInvocationID.y;
  if (col >= params.width || row >= params.height) return;
  const uint i = row * params.width + col;
  const float d = depth[i];
  const bool new_valid = d > 0.0 && d <= 3.4e38;
  const float z = uintBitsToFloat(zbuffer[i]);
  const bool covered = z < 3.4e38;
  const float d_w = covered ? z : 0.0;
  const float w = covered ? warped_weight[i] : 0.0;
  const bool old_valid = d_w > 0.0 && w > 0.0;
  float out_depth = 0.0, out_weight = 0.0;
  if (new_valid && old_valid) {
    const float sigma = 0.0012 + 0.0019 * (d - 0.4) * (d - 0.4);  // Kinect v1 axial noise
    if (abs(d - d_w) <= params.merge_threshold_m + 3.0 * sigma) {
      out_depth = (w * d_w + d) / (w + 1.0);
      out_weight = min(w + 1.0, params.max_weight);
    } else {
      out_depth = d;
      out_weight = 1.0;
    }
  } else if (new_valid) {
    out_depth = d;
    out_weight = 1.0;
  } else if (old_valid && w > 1.0) {
    out_depth = d_w;
    out_weight = w - 1.0;
  }
  merged[i] = out_depth;
  merged_weight[i] = out_weight;
}
