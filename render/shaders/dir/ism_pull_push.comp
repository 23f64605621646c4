#version 450
// Imperfect shadow maps, hole filling by pull-push (render/ism.h). Level 0 is the atlas itself
// (float bits), levels 1.. live in `pyramid`. Pull (mode 0): one invocation per texel of level
// `level` + 1 averages its valid children and is valid with at least two. Push (mode 1): one
// invocation per texel of level `level` fills a hole with its parent's value. The host runs the
// pulls from fine to coarse, then the pushes from coarse to fine.
layout(local_size_x = 64) in;

layout(std430, set = 0, binding = 0) buffer Atlas { float atlas[]; };
layout(std430, set = 0, binding = 1) buffer Pyramid { float pyramid[]; };

layout(push_constant) uniform Params {
  uint mode;
  uint tiles;
  uint fine_size;      // texels per side of level `level`
  uint fine_offset;    // into pyramid; unused for level 0
  uint coarse_offset;  // into pyramid
  uint fine_is_atlas;
  uint vpl_count;      // tile t belongs to VPL t % vpl_count
  uint first_emitter;  // push: tiles of VPLs from here on are not filled at this level
} params;

const float EMPTY = 1e30;

float read_fine(uint index) {
  return params.fine_is_atlas != 0u ? atlas[index] : pyramid[params.fine_offset + index];
}

void main() {
  // Dispatched as a 2D grid of groups where one row of groups would exceed the limit.
  const uint id = gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x + gl_GlobalInvocationID.x;
  const uint fine = params.fine_size, coarse = fine / 2u;
  if (params.mode == 0u) {
    if (id >= params.tiles * coarse * coarse) return;
    const uint tile = id / (coarse * coarse), x = id % coarse, y = (id / coarse) % coarse;
    float sum = 0.0;
    int valid = 0;
    for (uint k = 0u; k < 4u; ++k) {
      const float v = read_fine(tile * fine * fine + (2u * y + k / 2u) * fine + 2u * x + k % 2u);
      if (v < EMPTY) {
        sum += v;
        ++valid;
      }
    }
    pyramid[params.coarse_offset + id] = valid >= 2 ? sum / float(valid) : EMPTY;
  } else {
    if (id >= params.tiles * fine * fine) return;
    if (read_fine(id) < EMPTY) return;
    const uint tile = id / (fine * fine), x = id % fine, y = (id / fine) % fine;
    if (tile % params.vpl_count >= params.first_emitter) return;
    const float parent = pyramid[params.coarse_offset + tile * coarse * coarse + (y / 2u) * coarse + x / 2u];
    if (params.fine_is_atlas != 0u) atlas[id] = parent; else pyramid[params.fine_offset + id] = parent;
  }
}
