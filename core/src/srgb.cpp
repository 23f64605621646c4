#include "relight/core/srgb.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

namespace relight {

namespace {

std::array<float, 256> make_srgb8_table() {
  std::array<float, 256> table{};
  for (int i = 0; i < 256; ++i) {
    const double encoded = i / 255.0;
    table[static_cast<std::size_t>(i)] =
        static_cast<float>(encoded <= 0.04045 ? encoded / 12.92 : std::pow((encoded + 0.055) / 1.055, 2.4));
  }
  return table;
}

}  // namespace

float srgb_to_linear(float encoded) {
  return encoded <= 0.04045f ? encoded / 12.92f : std::pow((encoded + 0.055f) / 1.055f, 2.4f);
}

float linear_to_srgb(float linear) {
  const float c = std::clamp(linear, 0.f, 1.f);
  return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.f / 2.4f) - 0.055f;
}

const std::array<float, 256>& srgb8_linear_table() {
  static const std::array<float, 256> table = make_srgb8_table();
  return table;
}

float srgb8_to_linear(std::uint8_t encoded) { return srgb8_linear_table()[encoded]; }

Float3 decode_srgb8(const Rgb8& pixel) {
  return {srgb8_to_linear(pixel.r), srgb8_to_linear(pixel.g), srgb8_to_linear(pixel.b)};
}

namespace {

std::uint8_t encode_srgb8_exact(float c) { return static_cast<std::uint8_t>(std::lround(255.f * linear_to_srgb(c))); }

constexpr float kEncodeFloor = 0x1.0p-14f;  // below it every value encodes to 0 (code 1 starts at ~1.5e-4)
constexpr int kBucketShift = 15;            // 2^8 buckets per binade: none holds two thresholds

float float_of(std::uint32_t bits) {
  float out;
  std::memcpy(&out, &bits, sizeof out);
  return out;
}
std::uint32_t bits_of(float value) {
  std::uint32_t out;
  std::memcpy(&out, &value, sizeof out);
  return out;
}

/// The exact encoder's thresholds (thresholds[k]: the least float whose byte exceeds k, found by
/// bisection on the float ordering; thresholds[255] = infinity) and, per bucket of the floats in
/// [kEncodeFloor, 1], the byte at the bucket's start. A bucket spans a 256th of a binade, less
/// than the gap between two thresholds anywhere, so the search ends after a comparison or two.
struct SrgbEncoder {
  std::array<float, 256> thresholds{};
  std::vector<std::uint8_t> bucket_start;

  SrgbEncoder() {
    for (int k = 0; k < 255; ++k) {
      float lo = 0.f, hi = 1.f;  // encode(lo) <= k < encode(hi)
      while (std::nextafter(lo, 1.f) < hi) {
        const float mid = lo + 0.5f * (hi - lo);
        const float probe = mid > lo && mid < hi ? mid : std::nextafter(lo, 1.f);
        (encode_srgb8_exact(probe) > k ? hi : lo) = probe;
      }
      thresholds[static_cast<std::size_t>(k)] = hi;
    }
    thresholds[255] = std::numeric_limits<float>::infinity();
    const std::uint32_t first = bits_of(kEncodeFloor) >> kBucketShift, last = bits_of(1.f) >> kBucketShift;
    for (std::uint32_t bucket = first; bucket <= last; ++bucket)
      bucket_start.push_back(encode_srgb8_exact(float_of(bucket << kBucketShift)));
  }

  [[nodiscard]] std::uint8_t encode(float linear) const {
    if (!(linear >= kEncodeFloor)) return 0;  // NaN, negatives and the darkest values
    if (linear >= 1.f) return 255;
    const std::uint32_t bucket = (bits_of(linear) >> kBucketShift) - (bits_of(kEncodeFloor) >> kBucketShift);
    std::size_t code = bucket_start[bucket];
    while (linear >= thresholds[code]) ++code;
    return static_cast<std::uint8_t>(code);
  }
};

}  // namespace

std::uint8_t encode_srgb8_channel(float linear) {
  static const SrgbEncoder encoder;
  return encoder.encode(linear);
}

Rgb8 encode_srgb8(const Float3& linear) {
  return {encode_srgb8_channel(linear.x), encode_srgb8_channel(linear.y), encode_srgb8_channel(linear.z)};
}

}  // namespace relight
