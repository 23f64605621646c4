// Hierarchical warping (hierarchical_warp.h): the warped texels follow the importance map, never
// land on zero importance, keep a uniform map's stratification, and the Vulkan version picks the
// same texels as the CPU reference.
#include "relight/render/vpl/hierarchical_warp.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "support/vulkan_test_env.h"
#include "relight/core/error.h"
#include "relight/render/vpl/hierarchical_warp_vk.h"
#include "relight/render/scene/sampler.h"
#include "relight/vk/buffer.h"
#include "relight/vk/transfer.h"

namespace relight::render {
namespace {

/// 16x16: a zero quadrant, background 1, and three hot spots (40, 20, 10).
std::vector<float> hot_spot_map() {
  std::vector<float> map(16 * 16, 1.f);
  for (int y = 0; y < 8; ++y)
    for (int x = 8; x < 16; ++x) map[static_cast<std::size_t>(y * 16 + x)] = 0.f;
  map[3 * 16 + 2] = 40.f;
  map[12 * 16 + 12] = 20.f;
  map[9 * 16 + 5] = 10.f;
  return map;
}

/// size x size with a smooth ramp, scattered zeros and a few bright texels.
std::vector<float> mixed_map(int size) {
  std::vector<float> map(static_cast<std::size_t>(size) * static_cast<std::size_t>(size));
  Pcg32 random(11, 3);
  for (std::size_t i = 0; i < map.size(); ++i) {
    const float r = random.uniform();
    map[i] = r < 0.3f ? 0.f : (r > 0.995f ? 500.f * r : 0.1f + static_cast<float>(i % 97) * 0.01f);
  }
  return map;
}

std::vector<WarpPoint> random_points(std::uint32_t count, std::uint64_t seed) {
  std::vector<WarpPoint> points(count);
  Pcg32 random(seed, 1);
  for (WarpPoint& p : points) p = {random.uniform(), random.uniform()};
  return points;
}

/// Pearson's chi-square of the texel counts against count * probability, over texels with importance.
double chi_square(const std::vector<float>& map, const std::vector<WarpedTexel>& samples, int size, int& degrees) {
  std::vector<double> counts(map.size(), 0.0);
  for (const WarpedTexel& s : samples) counts[s.y * static_cast<std::uint32_t>(size) + s.x] += 1.0;
  double total = 0;
  for (float v : map) total += v;
  double chi2 = 0;
  degrees = -1;
  for (std::size_t i = 0; i < map.size(); ++i) {
    if (map[i] == 0.f) continue;
    const double expected = static_cast<double>(samples.size()) * map[i] / total;
    chi2 += (counts[i] - expected) * (counts[i] - expected) / expected;
    ++degrees;
  }
  return chi2;
}

TEST(HierarchicalWarp, PyramidLevelsSumTheirChildren) {
  const std::vector<float> map = mixed_map(32);
  const ImportancePyramid pyramid(map, 32);
  ASSERT_EQ(pyramid.levels(), 6);
  double total = 0;
  for (float v : map) total += v;
  EXPECT_NEAR(pyramid.total(), total, 1e-5 * total);
  for (int level = 1; level < pyramid.levels(); ++level) {
    const auto fine = pyramid.level(level - 1), coarse = pyramid.level(level);
    const std::size_t side = 32u >> level;
    for (std::size_t y = 0; y < side; ++y)
      for (std::size_t x = 0; x < side; ++x) {
        const std::size_t f = 2 * y * 2 * side + 2 * x;
        EXPECT_EQ(coarse[y * side + x], (fine[f] + fine[f + 1]) + (fine[f + 2 * side] + fine[f + 2 * side + 1]));
      }
  }
}

TEST(HierarchicalWarp, WarpedCountsFollowTheImportance) {
  // 200k random points: for a correct sampler chi-square over 190 degrees of freedom has mean 190
  // and deviation ~19.5, so 190 + 6 * 19.5 is passed by a correct sampler with probability
  // > 0.99999; a sampler off by 2 % on one hot spot alone adds ~70, a uniform one ~10^6.
  const std::vector<float> map = hot_spot_map();
  const ImportancePyramid pyramid(map, 16);
  const std::vector<WarpedTexel> samples = warp_points(pyramid, random_points(200000, 5));
  int degrees = 0;
  const double chi2 = chi_square(map, samples, 16, degrees);
  ASSERT_EQ(degrees, 16 * 16 - 64 - 1);
  EXPECT_LT(chi2, degrees + 6.0 * std::sqrt(2.0 * degrees)) << "degrees of freedom " << degrees;
  // The hot spot's share (40 of 259) to within 0.005, six standard deviations of a binomial count
  // (0.0008), while a hot spot sampled 5 % too rarely would be off by 0.008.
  double hot = 0;
  for (const WarpedTexel& s : samples) hot += (s.x == 2 && s.y == 3) ? 1.0 : 0.0;
  EXPECT_NEAR(hot / static_cast<double>(samples.size()), 40.0 / 259.0, 0.005);
}

TEST(HierarchicalWarp, ProbabilityIsImportanceOverTotal) {
  const std::vector<float> map = mixed_map(64);
  const ImportancePyramid pyramid(map, 64);
  for (const WarpedTexel& s : warp_points(pyramid, hammersley_points(4096))) {
    ASSERT_LT(s.x, 64u);
    ASSERT_LT(s.y, 64u);
    EXPECT_FLOAT_EQ(s.probability, map[s.y * 64 + s.x] / pyramid.total());
  }
}

TEST(HierarchicalWarp, NeverPicksZeroImportance) {
  std::vector<float> map = mixed_map(64);
  for (std::size_t i = 0; i < map.size(); i += 3) map[i] = 0.f;  // and whole zero rows of children
  std::vector<WarpPoint> points = hammersley_points(65536);
  for (float edge : {0.f, 0.5f, 0x1.fffffep-1f, 1.f, -1.f})
    for (float other : {0.f, 0.25f, 0x1.fffffep-1f}) points.insert(points.end(), {{edge, other}, {other, edge}});
  const ImportancePyramid pyramid(map, 64);
  for (const WarpedTexel& s : warp_points(pyramid, points)) {
    ASSERT_GT(map[s.y * 64 + s.x], 0.f) << "texel " << s.x << "," << s.y;
    ASSERT_GT(s.probability, 0.f);
  }
  // A single texel with importance takes every sample.
  std::vector<float> single(64 * 64, 0.f);
  single[37 * 64 + 5] = 0.25f;
  for (const WarpedTexel& s : warp_points(ImportancePyramid(single, 64), points)) {
    ASSERT_EQ(s.x, 5u);
    ASSERT_EQ(s.y, 37u);
    ASSERT_EQ(s.probability, 1.f);
  }
}

TEST(HierarchicalWarp, UniformMapKeepsThePointsStratification) {
  // Warping a constant map is the identity: point (u, v) lands in texel (floor(8u), floor(8v)),
  // so 64 Hammersley points fill the 8x8 map once per row-column stratum they occupy.
  const std::vector<float> map(64, 2.f);
  const std::vector<WarpPoint> points = hammersley_points(64);
  const std::vector<WarpedTexel> samples = warp_points(ImportancePyramid(map, 8), points);
  ASSERT_EQ(samples.size(), points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    EXPECT_EQ(samples[i].x, static_cast<std::uint32_t>(points[i].u * 8.f));
    EXPECT_EQ(samples[i].y, static_cast<std::uint32_t>(points[i].v * 8.f));
    EXPECT_EQ(samples[i].probability, 1.f / 64.f);
  }
}

TEST(HierarchicalWarp, AllZeroMapHasNoSamples) {
  const std::vector<float> zeros(16 * 16, 0.f);
  const ImportancePyramid pyramid(zeros, 16);
  EXPECT_EQ(pyramid.total(), 0.f);
  EXPECT_TRUE(warp_points(pyramid, hammersley_points(16)).empty());
  EXPECT_THROW((void)pyramid.warp({0.5f, 0.5f}), LogicError);
}

TEST(HierarchicalWarp, RejectsBadMaps) {
  std::vector<float> map(16, 1.f);
  EXPECT_THROW(ImportancePyramid(map, 3), Error);
  EXPECT_THROW(ImportancePyramid(map, 8), Error);
  map[5] = -1.f;
  EXPECT_THROW(ImportancePyramid(map, 4), Error);
  map[5] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(ImportancePyramid(map, 4), Error);
  map[5] = std::numeric_limits<float>::infinity();
  EXPECT_THROW(ImportancePyramid(map, 4), Error);
  map.assign(16, std::numeric_limits<float>::max());
  EXPECT_THROW(ImportancePyramid(map, 4), Error);
}

class HierarchicalWarpVkTest : public relight::test::VulkanTest {};

TEST_F(HierarchicalWarpVkTest, SameTexelsAsTheCpu) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  HierarchicalWarpVk warp(context);
  for (int size : {1, 2, 4, 16, 64, 256}) {  // every split of the levels over dispatches
    std::vector<float> map = mixed_map(size);
    if (size == 1) map[0] = 3.f;
    std::vector<WarpPoint> points = hammersley_points(4096);
    const std::vector<WarpPoint> random = random_points(4096, 9);
    points.insert(points.end(), random.begin(), random.end());
    const ImportancePyramid pyramid(map, size);
    const std::vector<WarpedTexel> cpu = warp_points(pyramid, points);
    const std::vector<WarpedTexel> gpu = warp.warp(map, size, points);
    ASSERT_EQ(gpu.size(), cpu.size());
    EXPECT_EQ(warp.download_pyramid(), std::vector<float>(pyramid.data().begin(), pyramid.data().end()))
        << "size " << size;
    int mismatches = 0;
    for (std::size_t i = 0; i < cpu.size(); ++i) {
      if (gpu[i].x != cpu[i].x || gpu[i].y != cpu[i].y) {
        if (++mismatches <= 5)
          ADD_FAILURE() << "size " << size << " point " << i << " (" << points[i].u << ", " << points[i].v << "): gpu "
                        << gpu[i].x << "," << gpu[i].y << " cpu " << cpu[i].x << "," << cpu[i].y;
        continue;
      }
      EXPECT_NEAR(gpu[i].probability, cpu[i].probability, 4e-7f * cpu[i].probability) << "size " << size;
    }
    EXPECT_EQ(mismatches, 0) << "size " << size;
  }
}

TEST_F(HierarchicalWarpVkTest, CountsFollowTheImportanceAndSkipZeros) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  HierarchicalWarpVk warp(context);
  const std::vector<float> map = hot_spot_map();
  const std::vector<WarpedTexel> samples = warp.warp(map, 16, random_points(200000, 5));
  ASSERT_EQ(samples.size(), 200000u);
  for (const WarpedTexel& s : samples) ASSERT_GT(map[s.y * 16 + s.x], 0.f);
  int degrees = 0;
  const double chi2 = chi_square(map, samples, 16, degrees);
  EXPECT_LT(chi2, degrees + 6.0 * std::sqrt(2.0 * degrees));
}

TEST_F(HierarchicalWarpVkTest, AllZeroMapMarksEverySampleEmpty) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  HierarchicalWarpVk warp(context);
  const std::vector<float> zeros(32 * 32, 0.f);
  EXPECT_TRUE(warp.warp(zeros, 32, hammersley_points(8)).empty());
  // The device path reports it per sample, so a frame graph needs no readback to skip them.
  vk::VulkanBuffer importance(context, zeros.size() * sizeof(float));
  vk::VulkanBuffer points(context, 8 * sizeof(WarpPoint));
  vk::VulkanBuffer samples(context, 8 * sizeof(WarpedTexel));
  context.transfer().upload(std::as_bytes(std::span(zeros)), importance);
  const std::vector<WarpPoint> hammersley = hammersley_points(8);
  context.transfer().upload(std::as_bytes(std::span(hammersley)), points);
  warp.run(importance, 32, points, 8, samples);
  std::vector<WarpedTexel> result(8);
  context.transfer().download(samples, std::as_writable_bytes(std::span(result)));
  for (const WarpedTexel& s : result) {
    EXPECT_EQ(s.x, 0xffffffffu);
    EXPECT_EQ(s.y, 0xffffffffu);
    EXPECT_EQ(s.probability, 0.f);
  }
  EXPECT_THROW(warp.run(importance, 24, points, 8, samples), LogicError);
}

}  // namespace
}  // namespace relight::render
