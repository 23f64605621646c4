#pragma once
// Plain pixel types shared by every stage. They are trivially copyable so that images can be
// uploaded to the GPU as they are, and they carry no Eigen/OpenCV dependency so this header
// stays cheap to include.
#include <cmath>
#include <cstdint>

namespace relight {

/// 8-bit sRGB-encoded colour, channel order R, G, B.
struct Rgb8 {
  std::uint8_t r = 0, g = 0, b = 0;
  friend bool operator==(const Rgb8&, const Rgb8&) = default;
};

/// An 8-bit camera channel at or above this code is taken as clipped: the light it recorded was
/// at least that bright, how much more is unknown (brdf/'s albedo and the composites leave it out).
inline constexpr int kClippedCode = 250;
inline bool has_clipped_channel(const Rgb8& c) {
  return c.r >= kClippedCode || c.g >= kClippedCode || c.b >= kClippedCode;
}

/// Three floats: a linear RGB radiance, a normal or a position, depending on the image alias.
struct Float3 {
  float x = 0.f, y = 0.f, z = 0.f;
  friend bool operator==(const Float3&, const Float3&) = default;
  Float3& operator+=(const Float3& o) { x += o.x; y += o.y; z += o.z; return *this; }
};

inline Float3 operator+(Float3 a, const Float3& b) { return a += b; }
inline Float3 operator-(const Float3& a, const Float3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Float3 operator*(float s, const Float3& a) { return {s * a.x, s * a.y, s * a.z}; }
inline float dot(const Float3& a, const Float3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline float length(const Float3& a) { return std::sqrt(dot(a, a)); }
/// Relative luminance Y of a linear sRGB (Rec. 709 primaries) colour.
inline float luminance(const Float3& c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

/// Depth in metres; 0 (and anything non-finite or negative) marks a missing measurement.
inline bool is_valid_depth(float metres) { return std::isfinite(metres) && metres > 0.f; }

/// A normal is valid when it is finite and not the zero vector (the invalid marker of NormalMap).
inline bool is_valid_normal(const Float3& n) {
  return std::isfinite(n.x) && std::isfinite(n.y) && std::isfinite(n.z) && dot(n, n) > 0.f;
}

}  // namespace relight
