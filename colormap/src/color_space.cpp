#include "relight/colormap/color_space.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

namespace relight::colormap {

namespace {

constexpr float kDelta = kLabDelta;
constexpr float kDeltaCubed = kLabDeltaCubed;
constexpr float kLinearSlope = kLabLinearSlope;

Float3 multiply(const float (&m)[3][3], const Float3& v) {
  return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z, m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
          m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
}

float lab_g(float t) { return t > kDeltaCubed ? std::cbrt(t) : t * kLinearSlope + 4.f / 29.f; }
float lab_g_inverse(float u) { return u > kDelta ? u * u * u : (u - 4.f / 29.f) / kLinearSlope; }

}  // namespace

Float3 linear_srgb_to_xyz(const Float3& rgb) { return multiply(kLinearSrgbToXyzE, rgb); }
Float3 xyz_to_linear_srgb(const Float3& xyz) { return multiply(kXyzEToLinearSrgb, xyz); }

LabPixel xyz_to_lab(const Float3& xyz) {
  const float gx = lab_g(xyz.x), gy = lab_g(xyz.y), gz = lab_g(xyz.z);
  return {116.f * gy - 16.f, 500.f * (gx - gy), 200.f * (gy - gz)};
}

Float3 lab_to_xyz(const LabPixel& lab) {
  const float gy = (lab.x + 16.f) / 116.f;
  return {lab_g_inverse(gy + lab.y / 500.f), lab_g_inverse(gy), lab_g_inverse(gy - lab.z / 200.f)};
}

LabPixel linear_srgb_to_lab(const Float3& rgb) { return xyz_to_lab(linear_srgb_to_xyz(rgb)); }
Float3 lab_to_linear_srgb(const LabPixel& lab) { return xyz_to_linear_srgb(lab_to_xyz(lab)); }

}  // namespace relight::colormap
