// GLSL twins of tone_map.h and color_space.h (same constants, same branches), included by the
// statistics shaders.
// GLSL matrices are column-major: each line below is one *column* of the C++ matrix.
const mat3 kLinearSrgbToXyzE = mat3(
    0.4969210174, 0.2562248996, 0.0232931727,
    0.3390896921, 0.6781793842, 0.1130298974,
    0.1639892905, 0.0655957162, 0.8636769299);
const mat3 kXyzEToLinearSrgb = mat3(
    2.6896551724, -1.0221081721, 0.0612244898,
    -1.2758620690, 1.9782866167, -0.2244897959,
    -0.4137931034, 0.0438215555, 1.1632653061);
const float kDelta = 6.0 / 29.0;
const float kDeltaCubed = kDelta * kDelta * kDelta;
const float kLinearSlope = 1.0 / (3.0 * kDelta * kDelta);

// tone_map.h: clamp(s * c * (1 + L / L_white^2) / (1 + L), 0, 1) with L = k * max channel of s * c.
vec3 tone_map(vec3 linear, ColormapToneMap tm) {
  const vec3 scaled = tm.exposure * linear;
  const float l = max(0.0, tm.compression * max(max(scaled.x, scaled.y), scaled.z));
  const float f = (1.0 + l * tm.inverse_white_squared) / (1.0 + l);
  return clamp(scaled * f, 0.0, 1.0);
}

float lab_g(float t) { return t > kDeltaCubed ? pow(t, 1.0 / 3.0) : t * kLinearSlope + 4.0 / 29.0; }
float lab_g_inverse(float u) { return u > kDelta ? u * u * u : (u - 4.0 / 29.0) / kLinearSlope; }

vec3 linear_srgb_to_lab(vec3 rgb) {
  const vec3 xyz = kLinearSrgbToXyzE * rgb;
  const float gx = lab_g(xyz.x), gy = lab_g(xyz.y), gz = lab_g(xyz.z);
  return vec3(116.0 * gy - 16.0, 500.0 * (gx - gy), 200.0 * (gy - gz));
}

vec3 lab_to_linear_srgb(vec3 lab) {
  const float gy = (lab.x + 16.0) / 116.0;
  const vec3 xyz = vec3(lab_g_inverse(gy + lab.y / 500.0), lab_g_inverse(gy), lab_g_inverse(gy - lab.z / 200.0));
  return kXyzEToLinearSrgb * xyz;
}

float srgb_to_linear(float encoded) {
  return encoded <= 0.04045 ? encoded / 12.92 : pow((encoded + 0.055) / 1.055, 2.4);
}
