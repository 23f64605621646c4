#version 450
// G-buffer pass: target 0 = (world position, signed distance), the sign holding r(p) as in
// Knecht et al. (positive: real surface, negative: virtual); target 1 = (normal facing the
// camera, material index); target 2 = (texture coordinates, footprint, tangent frame) on meshes
// with texture coordinates, else zero (GBuffer::texcoord and GBuffer::tangent: the footprint is
// the longer of the coordinates' screen derivatives, the GPU's form of gbuffer_cpu's ray
// differentials; the tangent frame comes from the same derivatives and those of the position,
// normal_map.h). Every corner carries
// its triangle's material and flags (a flat attribute: gl_PrimitiveID would need the
// geometry-shader feature).
layout(location = 0) in vec3 world_position;
layout(location = 1) in vec3 world_normal;
layout(location = 2) flat in uint triangle_info;  // bits 0-29: material index; bit 30: has texcoord; bit 31: virtual
layout(location = 3) in vec2 surface_texcoord;

#include "normal_map.glsl"

layout(push_constant) uniform Camera {
  mat4 world_to_clip;
  vec4 centre;
} camera;

layout(location = 0) out vec4 out_position;
layout(location = 1) out vec4 out_normal;
layout(location = 2) out vec4 out_texcoord;

void main() {
  const uint info = triangle_info;
  const bool is_virtual = (info >> 31) != 0u;
  const bool has_texcoord = ((info >> 30) & 1u) != 0u;
  const vec3 to_camera = camera.centre.xyz - world_position;
  const float distance = length(to_camera);
  vec3 n = normalize(world_normal);
  const float side = dot(n, to_camera) < 0.0 ? -1.0 : 1.0;
  n *= side;
  out_position = vec4(world_position, is_virtual ? -distance : distance);
  out_normal = vec4(n, float(info & 0x3fffffffu));
  // Derivatives before the branch: they need every invocation of the quad.
  const vec2 uv_dx = dFdx(surface_texcoord), uv_dy = dFdy(surface_texcoord);
  const vec3 p_dx = dFdx(world_position), p_dy = dFdy(world_position);
  const float footprint = max(length(uv_dx), length(uv_dy));
  // [dP/dx dP/dy] = [dP/du dP/dv] J with J = d(u, v) / d(x, y): invert J. Seen from the back,
  // the frame turns with the normal (normal_map.h flipped()).
  const float det = uv_dx.x * uv_dy.y - uv_dy.x * uv_dx.y;
  float frame = 0.0;
  if (has_texcoord && abs(det) > 0.0) {
    const vec3 dp_du = side * (p_dx * uv_dy.y - p_dy * uv_dx.y) / det;
    const vec3 dp_dv = side * (p_dy * uv_dx.x - p_dx * uv_dy.x) / det;
    vec3 tangent;
    float handedness;
    if (tangent_frame(dp_du, dp_dv, n, tangent, handedness)) frame = encode_tangent(tangent, handedness, n);
  }
  out_texcoord = has_texcoord ? vec4(surface_texcoord, max(footprint, 1e-12), frame) : vec4(0.0);
}
