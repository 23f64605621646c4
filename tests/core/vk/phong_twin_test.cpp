// The GLSL twin of the Phong model (core/shaders/phong.glsl) against core/phong.h: the same f and
// the same specular term for random directions, materials and exponents (1 to 1000), including
// pairs below the surface and lobes that miss the viewer.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <span>
#include <vector>

#include "relight/core/phong.h"
#include "relight/shaders/phong_twin_test_comp.h"
#include "relight/vk/buffer.h"
#include "relight/vk/compute_pipeline.h"
#include "relight/vk/transfer.h"
#include "support/vulkan_test_env.h"

namespace relight::vk {
namespace {

using PhongTwinTest = test::VulkanTest;

struct PhongCase {
  Phong material;
  Eigen::Vector3f normal, wi, wo;
};

Eigen::Vector3f random_unit(std::mt19937& rng) {
  std::normal_distribution<float> gauss;
  return Eigen::Vector3f(gauss(rng), gauss(rng), gauss(rng)).normalized();
}

std::vector<PhongCase> random_cases(std::size_t count) {
  std::mt19937 rng(20);
  std::uniform_real_distribution<float> unit(0.f, 1.f), log_n(0.f, 3.f);
  std::vector<PhongCase> cases(count);
  for (std::size_t i = 0; i < count; ++i) {
    PhongCase& c = cases[i];
    c.normal = random_unit(rng);
    c.wo = random_unit(rng);
    // Half the pairs near the mirror direction, so that the lobe is large as well as small.
    c.wi = i % 2 == 0 ? random_unit(rng) : (phong_reflect(c.wo, c.normal) + 0.1f * random_unit(rng)).normalized();
    c.material.kd = Eigen::Vector3f(unit(rng), unit(rng), unit(rng));
    c.material.ks = i % 5 == 0 ? 0.f : unit(rng);
    c.material.n = std::pow(10.f, log_n(rng));
  }
  return cases;
}

float lobe_tolerance(float n) { return 2e-5f + 1e-6f * n; }

TEST_F(PhongTwinTest, GlslTwinEvaluatesTheSameModelAsTheCpp) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  const std::vector<PhongCase> cases = random_cases(4096);
  std::vector<Eigen::Vector4f> packed;
  for (const PhongCase& c : cases) {
    packed.emplace_back(c.normal.x(), c.normal.y(), c.normal.z(), c.material.n);
    packed.emplace_back(c.wi.x(), c.wi.y(), c.wi.z(), 0.f);
    packed.emplace_back(c.wo.x(), c.wo.y(), c.wo.z(), 0.f);
    packed.emplace_back(c.material.kd.x(), c.material.kd.y(), c.material.kd.z(), c.material.ks);
  }
  const auto count = static_cast<std::uint32_t>(cases.size());
  VulkanBuffer input(context, packed.size() * sizeof(Eigen::Vector4f));
  VulkanBuffer output(context, cases.size() * sizeof(Eigen::Vector4f));
  context.transfer().upload(std::as_bytes(std::span(packed)), input);
  ComputePipeline pipeline(
      context,
      {.spirv = shaders::phong_twin_test_comp, .storage_buffers = 2, .push_constant_bytes = sizeof(std::uint32_t)});
  const auto set = pipeline.bind({&input, &output});
  context.submit(
      [&](VkCommandBuffer cmd) { pipeline.dispatch(cmd, set, count, ComputePipeline::group_count(count, 64), 1); });
  std::vector<Eigen::Vector4f> results(cases.size());
  context.transfer().download(output, std::as_writable_bytes(std::span(results)));

  int below = 0, lobes = 0;
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const PhongCase& c = cases[i];
    const Eigen::Vector3f f = phong_brdf(c.material, c.normal, c.wi, c.wo);
    const float specular = phong_specular(c.material.ks, c.material.n, phong_reflect(c.wi, c.normal).dot(c.wo));
    // pow(cos, n) turns cos's rounding (a few ulps, computed in a different order on the device)
    // into a relative error of about n ulps: the tolerance grows with the exponent. A wrong
    // normalisation ((n + 1) instead of (n + 2)) is a relative error of 1/n, far above it.
    const float relative = lobe_tolerance(c.material.n);
    for (int k = 0; k < 3; ++k) {
      ASSERT_NEAR(results[i][k], f[k], relative * (1.f + f[k])) << "case " << i << " channel " << k;
    }
    ASSERT_NEAR(results[i].w(), specular, relative * (1.f + specular)) << "case " << i;
    below += f.isZero();
    lobes += specular > 1.f;
  }
  // The table covers both sides of the surface and strong highlights, not only the diffuse part.
  EXPECT_GT(below, 1000);
  EXPECT_GT(lobes, 100);
}

TEST(Phong, CppTemplatesAgreeInFloatAndDouble) {
  const std::vector<PhongCase> cases = random_cases(512);
  for (const PhongCase& c : cases) {
    const Eigen::Vector3f f = phong_brdf(c.material, c.normal, c.wi, c.wo);
    const Eigen::Vector3d g =
        phong_brdf(c.material.cast<double>(), c.normal.cast<double>(), c.wi.cast<double>(), c.wo.cast<double>());
    EXPECT_LT((f.cast<double>() - g).cwiseAbs().maxCoeff(), lobe_tolerance(c.material.n) * (1.0 + g.maxCoeff()));
  }
}

}  // namespace
}  // namespace relight::vk
