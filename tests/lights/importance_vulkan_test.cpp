// The Vulkan importance sampler against the CPU reference: same pixels, same points.
#include <gtest/gtest.h>

#include "probes.h"
#include "relight/lights/importance_sampling.h"
#include "relight/vk/context.h"
#include "support/vulkan_test_env.h"

namespace relight::lights {
namespace {

class ImportanceVulkan : public test::VulkanTest {
 protected:
  static void expect_same_samples(const RadianceImage& probe, const ProbeGeometry& geometry,
                                  const ImportanceSamplingOptions& options, vk::VulkanContext& context) {
    std::vector<WarpedSample> cpu_samples, gpu_samples;
    ImportancePyramid pyramid;
    const LightSet cpu = sample_importance(probe, geometry, options, pyramid, &cpu_samples);
    ImportanceSamplerVk sampler(context, geometry);
    const LightSet gpu = sampler.run(probe, options, &gpu_samples);
    ASSERT_EQ(gpu_samples.size(), cpu_samples.size());
    int same_pixel = 0;
    for (std::size_t i = 0; i < cpu_samples.size(); ++i) {
      same_pixel += gpu_samples[i].pixel == cpu_samples[i].pixel ? 1 : 0;
      EXPECT_EQ(gpu_samples[i].pixel, cpu_samples[i].pixel) << "sample " << i;
      // Within the pixel the warp divides by the pixel's probability; a GPU that contracts to FMA
      // (NVIDIA does, lavapipe does not) moves the point inside its pixel by up to ~4e-4 of a pixel
      // (measured on an H200).
      EXPECT_NEAR(gpu_samples[i].u, cpu_samples[i].u, 1e-3) << "sample " << i;
      EXPECT_NEAR(gpu_samples[i].v, cpu_samples[i].v, 1e-3) << "sample " << i;
      EXPECT_LT(test::angle_between(gpu.lights[i].direction, cpu.lights[i].direction), 1e-4) << "sample " << i;
      EXPECT_NEAR(luminance(gpu.lights[i].power) / luminance(cpu.lights[i].power), 1.0, 1e-4) << "sample " << i;
    }
    EXPECT_EQ(same_pixel, options.samples);
  }
};

TEST_F(ImportanceVulkan, SyntheticProbeSameSamplesAsCpu) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  const test::SynthProbe& s = test::default_synth_probe();
  expect_same_samples(s.image, s.geometry, {64, 0}, context);
  expect_same_samples(s.image, s.geometry, {256, 12345}, context);
}

TEST_F(ImportanceVulkan, LatLongNonSquareProbeSameSamplesAsCpu) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  const ProbeGeometry geometry(ProbeCalibration::equirectangular(), 96, 40);
  const RadianceImage probe = test::emitter_probe(geometry, test::spherical(1.0, 2.0), 0.1, 50.0);
  expect_same_samples(probe, geometry, {100, 3}, context);
}

}  // namespace
}  // namespace relight::lights
