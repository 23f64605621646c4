// The statistics-based mapping: masked statistics against hand-computed values, the Reinhard
// transfer's defining property, delta_L confined to the virtual object, the colour error it
// leaves on the synthetic camera, and the Vulkan passes against the CPU reference.
#include "relight/colormap/statistics_transfer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <limits>

#include "colormap_test_scene.h"
#include "statistics_reference.h"
#include "support/vulkan_test_env.h"
#include "relight/colormap/statistics_transfer_vk.h"
#include "relight/core/error.h"
#include "relight/vk/buffer.h"
#include "relight/vk/transfer.h"

namespace relight::colormap {
namespace {

double lightness(double y) { return 116.0 * std::cbrt(y) - 16.0; }

TEST(StatisticsTransfer, MaskedStatisticsExcludeVirtualBlackAndInvalidPixels) {
  // Valid greys 0.125 and 1.0 (L* 42 and 100); the other pixels are each excluded for one reason.
  const float nan = std::numeric_limits<float>::quiet_NaN();
  RadianceImage real(6, 1), real_virtual(6, 1);
  ColorImage camera(6, 1, Rgb8{255, 255, 255});
  const float values[6] = {0.125f, 1.f, 0.5f, 0.5f, nan, 0.f};
  for (int c = 0; c < 6; ++c) real(0, c) = real_virtual(0, c) = {values[c], values[c], values[c]};
  real_virtual(0, 2) = {0.9f, 0.1f, 0.1f};  // virtual object
  camera(0, 3) = {0, 0, 0};                 // black camera pixel
  camera(0, 0) = {128, 128, 128};
  // pixel 4: NaN radiance; pixel 5: black rendering.
  const TransferStatistics s = masked_lab_statistics(real, real_virtual, camera, {});
  ASSERT_EQ(s.source.count, 2);
  EXPECT_NEAR(s.source.mean[0], (42.0 + 100.0) / 2, 1e-4);
  EXPECT_NEAR(s.source.stddev[0], 29.0, 1e-4);  // population standard deviation
  EXPECT_NEAR(s.source.mean[1], 0.0, 1e-4);
  EXPECT_NEAR(s.source.stddev[2], 0.0, 1e-4);
  const double camera_l = lightness(std::pow((128.0 / 255.0 + 0.055) / 1.055, 2.4));
  EXPECT_NEAR(s.target.mean[0], (camera_l + 100.0) / 2, 1e-3);
  EXPECT_NEAR(s.target.stddev[0], (100.0 - camera_l) / 2, 1e-3);
}

TEST(StatisticsTransfer, ReinhardTransferMovesSourceStatisticsOntoTarget) {
  TransferStatistics s;
  s.source = {100, {40.0, 5.0, -8.0}, {10.0, 4.0, 0.0}};
  s.target = {100, {55.0, -2.0, 6.0}, {20.0, 3.0, 7.0}};
  const ReinhardTransfer t = ReinhardTransfer::from(s);
  // Eq. 4.35-4.38: mu_s -> mu_t and mu_s + sigma_s -> mu_t + sigma_t per channel.
  const LabPixel mean = t.apply({40.f, 5.f, -8.f});
  const LabPixel plus_sigma = t.apply({50.f, 9.f, -8.f});
  EXPECT_NEAR(mean.x, 55.f, 1e-4f);
  EXPECT_NEAR(mean.y, -2.f, 1e-4f);
  EXPECT_NEAR(mean.z, 6.f, 1e-4f);
  EXPECT_NEAR(plus_sigma.x, 75.f, 1e-4f);
  EXPECT_NEAR(plus_sigma.y, 1.f, 1e-4f);
  EXPECT_FLOAT_EQ(t.scale[2], 1.f);  // sigma_s = 0: only the mean moves
  EXPECT_EQ(ReinhardTransfer::from({}).scale[0], 1.f);  // no valid pixel: identity
}

TEST(StatisticsTransfer, IdentityCameraGivesNearIdentityTransfer) {
  const auto& triple = test::orange_triple();
  ColorImage camera(triple.real.width(), triple.real.height());
  for (std::size_t i = 0; i < camera.size(); ++i) camera.pixels()[i] = encode_srgb8(tone_map(triple.real.pixels()[i], {}));
  const ReinhardTransfer t = ReinhardTransfer::from(masked_lab_statistics(triple.real, triple.real_virtual, camera, {}));
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(t.scale[k], 1.f, 0.01f) << k;   // 8-bit quantisation only
    EXPECT_NEAR(t.offset[k], 0.f, 0.3f) << k;  // Lab units
  }
}

TEST(StatisticsTransfer, DeltaIsExactlyZeroOutsideTheVirtualObject) {
  const auto& triple = test::orange_triple();
  RadianceImage delta;
  (void)statistics_color_map(triple.real, triple.real_virtual, triple.camera, {}, delta);
  const Mask mask = virtual_mask(triple.real, triple.real_virtual);
  int virtual_pixels = 0, nonzero_inside = 0;
  for (std::size_t i = 0; i < delta.size(); ++i) {
    if (mask.pixels()[i] == 0) {
      ASSERT_EQ(delta.pixels()[i], Float3{}) << "pixel " << i;
    } else {
      ++virtual_pixels;
      nonzero_inside += delta.pixels()[i] == Float3{} ? 0 : 1;
    }
  }
  EXPECT_GT(virtual_pixels, 200);  // the sphere is really in view
  EXPECT_GT(nonzero_inside, virtual_pixels * 9 / 10);
  // The composite keeps every real pixel of the camera image bit for bit.
  const ColorImage mapped = composite(triple.camera, delta);
  for (std::size_t i = 0; i < delta.size(); ++i) {
    if (mask.pixels()[i] == 0) {
      ASSERT_EQ(mapped.pixels()[i], triple.camera.pixels()[i]);
    }
  }
}

TEST(StatisticsTransfer, ReducesTheColourErrorOfTheVirtualObject) {
  for (const auto* triple : {&test::orange_triple(), &test::green_triple()}) {
    RadianceImage identity, mapped;
    (void)statistics_color_map(triple->real, triple->real_virtual, triple->camera, {}, mapped);
    const ReinhardTransfer none;
    statistics_delta(triple->real, triple->real_virtual, none, {}, identity);
    const double before = test::virtual_delta_e(*triple, identity);
    const double after = test::virtual_delta_e(*triple, mapped);
    std::printf("[ colormap ] statistics: mean CIEDE2000 before %.2f after %.2f (%s sphere)\n", before, after,
                triple == &test::orange_triple() ? "orange" : "green");
    // Measured: orange 7.25 -> 2.66, green 8.06 -> 3.57 (per-channel Lab statistics cannot undo
    // the crosstalk exactly, and the green sphere's statistics are not in the real scene).
    EXPECT_GT(before, 6.0);
    EXPECT_LT(after, 4.0);
    EXPECT_LT(after, 0.5 * before);
  }
}

TEST(StatisticsTransfer, FastCubeRootMatchesStdCbrt) {
  // Every 101st float from delta^3 / 2 to 8: the Lab range [delta^3, 1] of the in-gamut colours
  // and well beyond (about 1.6 million values, every mantissa region of every octave).
  double worst = 0.0;
  const auto last = std::bit_cast<std::int32_t>(8.f);
  for (auto bits = std::bit_cast<std::int32_t>(0.5f * kLabDeltaCubed); bits < last; bits += 101) {
    const float x = std::bit_cast<float>(bits);
    const double exact = std::cbrt(static_cast<double>(x));
    worst = std::max(worst, std::fabs(fast_cbrt(x) - exact) / exact);
  }
  EXPECT_LT(worst, 6e-7);  // std::cbrt in float: 1e-7
  EXPECT_NEAR(fast_cbrt(1.f), 1.f, 1e-6f);
  EXPECT_NEAR(fast_cbrt(0.125f), 0.5f, 1e-6f);
  // The branch-free g keeps the linear part below delta^3 (and at t <= 0, where fast_cbrt is garbage).
  EXPECT_FLOAT_EQ(lab_g_fast(0.f), 4.f / 29.f);
  EXPECT_FLOAT_EQ(lab_g_fast(-0.01f), -0.01f * kLabLinearSlope + 4.f / 29.f);
}

// The synthetic triple with the kinds of pixels the mask must drop mixed in: NaN and infinite
// radiance, black camera pixels, black renderings.
truth::SyntheticTriple triple_with_invalid_pixels() {
  truth::SyntheticTriple triple = test::orange_triple();
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  for (std::size_t i = 0; i < triple.real.size(); i += 7) {
    switch (i % 4) {
      case 0: triple.real.pixels()[i] = triple.real_virtual.pixels()[i] = {nan, 0.5f, 0.5f}; break;
      case 1: triple.real.pixels()[i] = triple.real_virtual.pixels()[i] = {inf, inf, inf}; break;
      case 2: triple.camera.pixels()[i] = {0, 0, 0}; break;
      default: triple.real.pixels()[i] = triple.real_virtual.pixels()[i] = {0.f, -1.f, 0.f}; break;
    }
  }
  return triple;
}

void expect_statistics_near(const LabStatistics& fast, const LabStatistics& reference, double tolerance) {
  EXPECT_EQ(fast.count, reference.count);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_NEAR(fast.mean[k], reference.mean[k], tolerance) << k;
    EXPECT_NEAR(fast.stddev[k], reference.stddev[k], tolerance) << k;
  }
}

void expect_fast_mapping_matches_reference(const truth::SyntheticTriple& triple, const ToneMap& tm) {
  const ReinhardTransfer reference = ReinhardTransfer::from(
      statistics_from_sums(test::masked_lab_sums_reference(triple.real, triple.real_virtual, triple.camera, tm)));
  const RadianceImage reference_delta =
      test::statistics_delta_reference(triple.real, triple.real_virtual, reference, tm);
  RadianceImage delta;
  const ReinhardTransfer fast = statistics_color_map(triple.real, triple.real_virtual, triple.camera, tm, delta);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_NEAR(fast.scale[k], reference.scale[k], 1e-5f * reference.scale[k]) << k;
    EXPECT_NEAR(fast.offset[k], reference.offset[k], 1e-3f) << k;
  }
  float worst = 0.f;
  for (std::size_t i = 0; i < delta.size(); ++i) {
    const Float3 d = delta.pixels()[i] - reference_delta.pixels()[i];
    worst = std::max({worst, std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)});
  }
  EXPECT_LT(worst, 1e-5f);
  EXPECT_NEAR(test::virtual_delta_e(triple, delta), test::virtual_delta_e(triple, reference_delta), 1e-3);
}

/// Both operators of tone_map.h: the exposure clamp, and Reinhard's with a scale and a white that
/// compress the triples' range (so the eight-lane and GLSL versions of the factor are exercised).
std::vector<ToneMap> both_tone_maps() {
  return {ToneMap{}, ToneMap{.op = ToneOperator::Reinhard, .exposure = 1.7f, .inverse_white_squared = 0.25f}};
}

TEST(StatisticsTransfer, FastStatisticsMatchThePlainReference) {
  for (const ToneMap& tm : both_tone_maps()) {
    for (const truth::SyntheticTriple& triple :
         {test::orange_triple(), test::green_triple(), triple_with_invalid_pixels()}) {
      const TransferStatistics reference =
          statistics_from_sums(test::masked_lab_sums_reference(triple.real, triple.real_virtual, triple.camera, tm));
      const TransferStatistics fast = masked_lab_statistics(triple.real, triple.real_virtual, triple.camera, tm);
      ASSERT_GT(reference.source.count, 1000);
      // Lab units: fast_cbrt's 5e-7 relative is at most 116 * 5e-7 = 6e-5 in L* per pixel.
      expect_statistics_near(fast.source, reference.source, 1e-4);
      expect_statistics_near(fast.target, reference.target, 1e-4);
    }
  }
}

TEST(StatisticsTransfer, FastMappingMatchesThePlainReference) {
  for (const ToneMap& tm : both_tone_maps()) {
    for (const truth::SyntheticTriple* triple : {&test::orange_triple(), &test::green_triple()}) {
      SCOPED_TRACE(tm.op == ToneOperator::Reinhard ? "reinhard" : "exposure");
      expect_fast_mapping_matches_reference(*triple, tm);
    }
  }
}

TEST(StatisticsTransfer, ResultDoesNotDependOnTheThreadCount) {
  const truth::SyntheticTriple triple = triple_with_invalid_pixels();
  const LabSums one = masked_lab_sums(triple.real, triple.real_virtual, triple.camera, {}, 1);
  for (const int threads : {2, 3, 8}) {
    const LabSums many = masked_lab_sums(triple.real, triple.real_virtual, triple.camera, {}, threads);
    EXPECT_EQ(many.count, one.count);
    EXPECT_EQ(many.source_sum, one.source_sum) << threads;  // bit for bit: fixed summation order
    EXPECT_EQ(many.source_sum_sq, one.source_sum_sq) << threads;
    EXPECT_EQ(many.target_sum, one.target_sum) << threads;
    EXPECT_EQ(many.target_sum_sq, one.target_sum_sq) << threads;
    RadianceImage delta_one, delta_many;
    statistics_delta(triple.real, triple.real_virtual, {}, {}, delta_one, 1);
    statistics_delta(triple.real, triple.real_virtual, {}, {}, delta_many, threads);
    // Bytes, not floats: the NaN pixels give NaN deltas, which compare unequal to themselves.
    EXPECT_TRUE(std::ranges::equal(delta_one.bytes(), delta_many.bytes())) << threads;
  }
}

TEST(StatisticsTransfer, MismatchedSizesAreAClearError) {
  RadianceImage delta;
  EXPECT_THROW((void)statistics_color_map(RadianceImage(4, 4), RadianceImage(4, 4), ColorImage(4, 2), {}, delta),
               Error);
}

class StatisticsTransferVulkan : public ::relight::test::VulkanTest {};

void expect_vulkan_matches_cpu(vk::VulkanContext& context, const ToneMap& tm) {
  const auto& triple = test::orange_triple();
  StatisticsColorMapVk vulkan(context);
  vulkan.set_tone_map(tm);
  RadianceImage gpu_delta;
  const ReinhardTransfer gpu = vulkan.run(triple.real, triple.real_virtual, triple.camera, gpu_delta);
  const TransferStatistics cpu_stats = masked_lab_statistics(triple.real, triple.real_virtual, triple.camera, tm);
  const ReinhardTransfer cpu = ReinhardTransfer::from(cpu_stats);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(gpu.scale[k], cpu.scale[k], 1e-4f * std::fabs(cpu.scale[k])) << k;
    EXPECT_NEAR(gpu.offset[k], cpu.offset[k], 2e-3f) << k;
  }
  RadianceImage cpu_delta;
  statistics_delta(triple.real, triple.real_virtual, cpu, tm, cpu_delta);
  ASSERT_TRUE(gpu_delta.same_shape(cpu_delta));
  float worst = 0.f;
  for (std::size_t i = 0; i < cpu_delta.size(); ++i) {
    const Float3 d = gpu_delta.pixels()[i] - cpu_delta.pixels()[i];
    worst = std::max({worst, std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)});
  }
  EXPECT_LT(worst, 1e-4f);
  EXPECT_GT(test::virtual_delta_e(triple, cpu_delta), 0.0);
}

TEST_F(StatisticsTransferVulkan, ReductionAndTransferMatchTheCpuReference) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  for (const ToneMap& tm : both_tone_maps()) {
    SCOPED_TRACE(tm.op == ToneOperator::Reinhard ? "reinhard" : "exposure");
    expect_vulkan_matches_cpu(context, tm);
  }
}

TEST_F(StatisticsTransferVulkan, CountsAreExactWithAPartialLastWorkGroup) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  // 4 x 75 = 300 pixels: one full group of 256 and a partial one; every pixel valid.
  RadianceImage real(4, 75, Float3{0.3f, 0.2f, 0.1f});
  ColorImage camera(4, 75, Rgb8{90, 80, 70});
  vk::VulkanBuffer r(context, real.bytes().size()), c(context, camera.bytes().size());
  context.transfer().upload(real.bytes(), r);
  context.transfer().upload(camera.bytes(), c);
  StatisticsColorMapVk vulkan(context);
  const LabSums sums = vulkan.reduce(r, r, c, 4, 75);
  EXPECT_EQ(sums.count, 300);
  const TransferStatistics s = statistics_from_sums(sums);
  const LabPixel expected = linear_srgb_to_lab({0.3f, 0.2f, 0.1f});
  EXPECT_NEAR(s.source.mean[0], expected.x, 1e-3);
  EXPECT_NEAR(s.source.mean[1], expected.y, 1e-3);
  EXPECT_NEAR(s.source.stddev[0], 0.0, 0.05);
}

TEST_F(StatisticsTransferVulkan, RejectsSizesThatAreNotAMultipleOf4) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  StatisticsColorMapVk vulkan(context);
  RadianceImage delta;
  EXPECT_THROW((void)vulkan.run(RadianceImage(3, 3), RadianceImage(3, 3), ColorImage(3, 3), delta), Error);
}

}  // namespace
}  // namespace relight::colormap
