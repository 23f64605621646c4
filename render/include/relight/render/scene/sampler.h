#pragma once
// A small deterministic random stream per (seed, pixel, sample): PCG32 (O'Neill 2014) seeded
// through SplitMix64. Seeding per sample rather than per thread makes every pixel's value
// independent of the thread count and of how the progressive passes split the samples.
#include <algorithm>
#include <array>
#include <cstdint>

namespace relight::render {

class Pcg32 {
 public:
  Pcg32(std::uint64_t seed, std::uint64_t stream) {
    increment_ = (splitmix(stream) << 1u) | 1u;
    state_ = 0;
    next();
    state_ += splitmix(seed);
    next();
  }
  /// Stream for sample `sample` of pixel `pixel` under the render seed `seed`.
  static Pcg32 for_sample(std::uint64_t seed, std::uint64_t pixel, std::uint64_t sample) {
    return Pcg32(seed ^ splitmix(sample + 0x632be59bd9b4e019ull), pixel);
  }

  std::uint32_t next() {
    const std::uint64_t old = state_;
    state_ = old * 6364136223846793005ull + increment_;
    const auto xorshifted = static_cast<std::uint32_t>(((old >> 18u) ^ old) >> 27u);
    const auto rot = static_cast<std::uint32_t>(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((~rot + 1u) & 31u));
  }
  /// Uniform in [0, 1).
  float uniform() { return static_cast<float>(next() >> 8) * 0x1p-24f; }

 private:
  static std::uint64_t splitmix(std::uint64_t x) {
    x += 0x9e3779b97f4a7c15ull;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
    return x ^ (x >> 31);
  }

  std::uint64_t state_ = 0;
  std::uint64_t increment_ = 1;
};

/// Point `index` of the Halton sequence in bases 2 and 3, both coordinates shifted by `shift`
/// modulo 1 (Cranley-Patterson rotation, as lights::hammersley_point's). Unlike the Hammersley
/// set's, any run of consecutive indices is itself spread evenly: for samples whose indices are
/// shared out among several sources in runs.
inline std::array<float, 2> rotated_halton(std::uint32_t index, std::array<float, 2> shift) {
  const auto radical_inverse = [](std::uint32_t i, std::uint32_t base) {
    double inverse_base = 1.0 / base, factor = inverse_base, value = 0.0;
    for (; i > 0; i /= base, factor *= inverse_base) value += static_cast<double>(i % base) * factor;
    return static_cast<float>(std::min(value, 1.0 - 0x1p-24));
  };
  const auto wrap = [](float v) { return v >= 1.f ? v - 1.f : v; };
  return {wrap(radical_inverse(index, 2) + shift[0]), wrap(radical_inverse(index, 3) + shift[1])};
}

}  // namespace relight::render
