#version 450
// G-buffer pass (render/gbuffer_vk.h): world-space position, normal and texture coordinates to
// the fragment shader.
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in uint info;  // bits 0-29: material index; bit 30: has texcoord; bit 31: virtual
layout(location = 3) in vec2 texcoord;

layout(push_constant) uniform Camera {
  mat4 world_to_clip;
  vec4 centre;  // camera centre (world), w unused
} camera;

layout(location = 0) out vec3 world_position;
layout(location = 1) out vec3 world_normal;
layout(location = 2) flat out uint triangle_info;
layout(location = 3) out vec2 surface_texcoord;

void main() {
  world_position = position;
  world_normal = normal;
  triangle_info = info;
  surface_texcoord = texcoord;
  gl_Position = camera.world_to_clip * vec4(position, 1.0);
}
