#version 450
// Shadow-map pass (render/shadow_maps.h): each texel keeps the light depth of the nearest
// surface - the distance to a point or spot light, or the distance along a directional light.
layout(location = 0) in vec3 world_position;

layout(push_constant) uniform View {
  mat4 world_to_clip;
  vec4 eye;  // w = 1: light position; w = 0: unit direction towards the light
} view;

layout(location = 0) out float light_depth;

void main() {
  light_depth = view.eye.w > 0.5 ? length(world_position - view.eye.xyz) : -dot(world_position, view.eye.xyz);
}
