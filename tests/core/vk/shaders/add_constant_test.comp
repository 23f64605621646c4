#version 450
// Test shader for the Vulkan layer: output[i] = input[i] + params.add for i < params.count.
layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) readonly buffer Input { float input_values[]; };
layout(std430, set = 0, binding = 1) writeonly buffer Output { float output_values[]; };
layout(push_constant) uniform Params {
  uint count;
  float add;
} params;

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i < params.count) output_values[i] = input_values[i] + params.add;
}
