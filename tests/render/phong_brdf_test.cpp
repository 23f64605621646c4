#include "relight/render/scene/phong_brdf.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "relight/render/scene/sampler.h"

namespace relight::render {
namespace {

const Eigen::Vector3f kUp(0, 0, 1);

PhongMaterial glossy() {
  PhongMaterial m;
  m.kd = {0.3f, 0.2f, 0.1f};
  m.ks = 0.4f;
  m.n = 40.f;
  return m;
}

TEST(PhongBrdf, IsSymmetricAndZeroBelowTheSurface) {
  const PhongMaterial m = glossy();
  const Eigen::Vector3f a = Eigen::Vector3f(0.3f, 0.1f, 0.9f).normalized();
  const Eigen::Vector3f b = Eigen::Vector3f(-0.2f, -0.1f, 0.95f).normalized();
  EXPECT_TRUE(phong_brdf(m, kUp, a, b).isApprox(phong_brdf(m, kUp, b, a), 1e-6f));
  EXPECT_TRUE(phong_brdf(m, kUp, Eigen::Vector3f(0.3f, 0.f, -0.9f).normalized(), b).isZero());
}

TEST(PhongBrdf, LambertianAlbedoIntegratesToKd) {
  // The directional albedo of a diffuse surface is k_d for every view: integrate f cos over the
  // hemisphere by importance sampling (weight = f cos / pdf).
  PhongMaterial m;
  m.kd = {0.7f, 0.5f, 0.2f};
  const Eigen::Vector3f wo = Eigen::Vector3f(0.4f, 0.f, 0.9f).normalized();
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  const int n = 20000;
  Pcg32 rng(7, 1);
  for (int i = 0; i < n; ++i) {
    const auto s = sample_phong(m, kUp, wo, rng.uniform(), rng.uniform());
    ASSERT_TRUE(s.has_value());
    sum += s->weight.cast<double>();
  }
  EXPECT_NEAR(sum.x() / n, 0.7, 1e-5);  // weight is exactly k_d for a cosine-sampled Lambertian
  EXPECT_NEAR(sum.z() / n, 0.2, 1e-5);
}

TEST(PhongBrdf, SampledWeightsAgreeWithUniformHemisphereQuadrature) {
  // Both estimate the reflected fraction of light  rho(wo) = integral f cos dwi.
  const PhongMaterial m = glossy();
  const Eigen::Vector3f wo = Eigen::Vector3f(0.5f, 0.2f, 0.8f).normalized();
  Pcg32 rng(11, 2);
  double sampled = 0.0, uniform = 0.0;
  const int n = 400000;
  for (int i = 0; i < n; ++i) {
    if (const auto s = sample_phong(m, kUp, wo, rng.uniform(), rng.uniform())) sampled += s->weight.x();
    const float z = rng.uniform();
    const float phi = 2.f * std::numbers::pi_v<float> * rng.uniform();
    const float r = std::sqrt(1.f - z * z);
    const Eigen::Vector3f wi(r * std::cos(phi), r * std::sin(phi), z);
    uniform += phong_brdf(m, kUp, wi, wo).x() * z * 2.0 * std::numbers::pi;
  }
  EXPECT_NEAR(sampled / n, uniform / n, 0.01);
  EXPECT_LT(sampled / n, 1.0);  // energy conserving for k_d + k_s <= 1
}

TEST(PhongBrdf, PdfIntegratesToAtMostOne) {
  const PhongMaterial m = glossy();
  const Eigen::Vector3f wo = Eigen::Vector3f(0.1f, 0.3f, 0.9f).normalized();
  Pcg32 rng(3, 4);
  double integral = 0.0;
  const int n = 400000;
  for (int i = 0; i < n; ++i) {
    const float z = 2.f * rng.uniform() - 1.f;
    const float phi = 2.f * std::numbers::pi_v<float> * rng.uniform();
    const float r = std::sqrt(std::max(0.f, 1.f - z * z));
    integral += phong_pdf(m, kUp, Eigen::Vector3f(r * std::cos(phi), r * std::sin(phi), z), wo) * 4.0 * std::numbers::pi;
  }
  // The specular lobe around r(wo) loses the part below the horizon; the rest integrates to 1.
  EXPECT_LE(integral / n, 1.01);
  EXPECT_GT(integral / n, 0.95);
}

TEST(Sampler, SameSeedSameStreamAndUniformRange) {
  Pcg32 a = Pcg32::for_sample(5, 100, 3), b = Pcg32::for_sample(5, 100, 3), c = Pcg32::for_sample(5, 100, 4);
  double mean = 0.0;
  bool differs = false;
  for (int i = 0; i < 10000; ++i) {
    const float x = a.uniform();
    EXPECT_EQ(x, b.uniform());
    differs |= x != c.uniform();
    ASSERT_GE(x, 0.f);
    ASSERT_LT(x, 1.f);
    mean += x;
  }
  EXPECT_TRUE(differs);
  EXPECT_NEAR(mean / 10000, 0.5, 0.01);
}

}  // namespace
}  // namespace relight::render
