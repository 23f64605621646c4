#include "relight/render/scene/sampler.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace relight::render {
namespace {

/// The point with the rotation taken back out (modulo 1).
std::array<float, 2> unshifted(std::array<float, 2> p, std::array<float, 2> shift) {
  const auto back = [](float v, float s) { return v - s < 0.f ? v - s + 1.f : v - s; };
  return {back(p[0], shift[0]), back(p[1], shift[1])};
}

// Any 2^k consecutive Halton indices put one point into each 1/2^k of the first coordinate and
// any 3^k one into each 1/3^k of the second, wherever the run starts: a source that gets a run
// of photon indices gets its directions spread evenly.
TEST(Sampler, AnyRunOfHaltonPointsIsStratified) {
  const std::array<float, 2> shift{0.6f, 0.15f};
  for (const std::uint32_t start : {0u, 1u, 977u, 65531u}) {
    std::vector<int> halves(64, 0), thirds(81, 0);
    for (std::uint32_t i = start; i < start + 81; ++i) {
      const auto [u, v] = unshifted(rotated_halton(i, shift), shift);
      if (i < start + 64) ++halves[static_cast<std::size_t>(std::min(63.f, std::floor((u + 1e-6f) * 64.f)))];
      ++thirds[static_cast<std::size_t>(std::min(80.f, std::floor((v + 1e-6f) * 81.f)))];
    }
    for (const int count : halves) EXPECT_EQ(count, 1) << "run from " << start;
    for (const int count : thirds) EXPECT_EQ(count, 1) << "run from " << start;
  }
}

}  // namespace
}  // namespace relight::render
