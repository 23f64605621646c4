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

// Hammersley's 256 points form a (0, 8, 2)-net in base 2: every box of 1/2^a x 1/2^(8 - a) holds
// exactly one point. The rotation moves the set without breaking that (modulo 1), and every
// point stays in the unit square.
TEST(Sampler, RotatedHammersleyIsANetInEveryShapeOfBox) {
  const std::array<float, 2> shift{0.37f, 0.81f};
  constexpr std::uint32_t kCount = 256;
  for (int a = 0; a <= 8; ++a) {
    const int nx = 1 << a, ny = kCount / nx;
    std::vector<int> boxes(static_cast<std::size_t>(nx * ny), 0);
    for (std::uint32_t i = 0; i < kCount; ++i) {
      const auto p = rotated_hammersley(i, kCount, shift);
      ASSERT_GE(p[0], 0.f);
      ASSERT_LT(p[0], 1.f);
      ASSERT_GE(p[1], 0.f);
      ASSERT_LT(p[1], 1.f);
      const auto [u, v] = unshifted(p, shift);
      // A hair inside, against float rounding of the shift at a box's edge.
      const int x = std::min(nx - 1, static_cast<int>(std::floor((u + 1e-6f) * static_cast<float>(nx))));
      const int y = std::min(ny - 1, static_cast<int>(std::floor((v + 1e-6f) * static_cast<float>(ny))));
      ++boxes[static_cast<std::size_t>(y) * static_cast<std::size_t>(nx) + static_cast<std::size_t>(x)];
    }
    for (const int count : boxes) ASSERT_EQ(count, 1) << nx << " x " << ny << " boxes";
  }
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
