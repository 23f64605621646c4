// Normal maps: the GLSL twin of render/scene/normal_map.h (each function mirrors its namesake).
#ifndef RELIGHT_NORMAL_MAP_GLSL
#define RELIGHT_NORMAL_MAP_GLSL
#include "basis.glsl"

// tangent_frame(dp_du, dp_dv, normal): false where the coordinates do not span the surface.
bool tangent_frame(vec3 dp_du, vec3 dp_dv, vec3 n, out vec3 tangent, out float handedness) {
  const vec3 along = dp_du - n * dot(n, dp_du);
  const float len = length(along);
  tangent = vec3(0.0);
  handedness = 1.0;
  if (!(len > 1e-12) || isinf(len) || isnan(len)) return false;
  tangent = along / len;
  handedness = dot(cross(n, tangent), dp_dv) <= 0.0 ? 1.0 : -1.0;
  return true;
}

float encode_tangent(vec3 tangent, float handedness, vec3 n) {
  vec3 t, b;
  orthonormal_basis(n, t, b);
  return atan(dot(tangent, b), dot(tangent, t)) + (handedness > 0.0 ? 4.0 : 12.0);
}

// decode_tangent(): false for code 0 (no frame).
bool decode_tangent(float code, vec3 n, out vec3 tangent, out float handedness) {
  tangent = vec3(0.0);
  handedness = 1.0;
  if (!(code > 0.0)) return false;
  const bool right_handed = code < 8.0;
  const float angle = code - (right_handed ? 4.0 : 12.0);
  vec3 t, b;
  orthonormal_basis(n, t, b);
  tangent = cos(angle) * t + sin(angle) * b;
  handedness = right_handed ? 1.0 : -1.0;
  return true;
}

vec3 mapped_normal(vec3 n, vec3 tangent, float handedness, vec3 texel, float scale) {
  const vec3 m = 2.0 * texel - 1.0;
  const vec3 bitangent = handedness * cross(n, tangent);
  const vec3 bent = scale * m.x * tangent + scale * m.y * bitangent + m.z * n;
  const float len = length(bent);
  return len > 1e-6 && !isinf(len) && !isnan(len) ? bent / len : n;
}
#endif
