#pragma once
// Seeding and sampling that give the same numbers on every platform and thread schedule.
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>

namespace relight::synth::detail {

/// SplitMix64 finaliser: decorrelates nearby seeds (frame 1 vs 2, row 7 vs 8).
inline std::uint64_t mix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

inline std::uint64_t stream_seed(std::uint64_t seed, std::uint64_t stream, std::uint64_t index) {
  return mix(mix(mix(seed) ^ stream) ^ index);
}

/// Uniform in [0, 1) from the top 53 bits.
inline double uniform(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

/// Standard normal by Box-Muller (one of the pair; two draws per call, always).
inline double gaussian(std::mt19937_64& rng) {
  const double u1 = 1.0 - uniform(rng);  // (0, 1], so log() stays finite
  const double u2 = uniform(rng);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

}  // namespace relight::synth::detail
