#version 450
// Shadow-map pass (render/shadow_maps.h): world position to the fragment shader, which stores
// its light depth.
layout(location = 0) in vec3 position;

layout(push_constant) uniform View {
  mat4 world_to_clip;
  vec4 eye;
} view;

layout(location = 0) out vec3 world_position;

void main() {
  world_position = position;
  gl_Position = view.world_to_clip * vec4(position, 1.0);
}
