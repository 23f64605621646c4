// The Vulkan K-means engine against the CPU engine: for the same initial centres every step
// gives identical exact sums, so the runs agree in labels, centres, compactness and iterations.
#include "relight/brdf/kmeans_vk.h"

#include <gtest/gtest.h>

#include <random>

#include "brdf_test_scene.h"
#include "support/vulkan_test_env.h"
#include "relight/brdf/diffuse.h"
#include "relight/brdf/highlight.h"

namespace relight::brdf {
namespace {

class KMeansVkTest : public test::VulkanTest {};

std::vector<Float3> scene_kd_points() {
  const test::BrdfScene& s = test::brdf_scene();
  ColorImage cleaned;
  Mask highlights, valid;
  remove_highlights(s.color, {}, cleaned, highlights);
  RadianceImage kd;
  estimate_diffuse(cleaned, s.positions, s.truth.normals, s.lights, {}, kd, valid);
  std::vector<Float3> points;
  for (std::size_t i = 0; i < kd.size(); ++i) {
    if (valid.pixels()[i]) points.push_back(kmeans_feature(kd.pixels()[i]));
  }
  return points;
}

TEST_F(KMeansVkTest, StepSumsEqualTheCpuEngine) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<float> unit(0.f, 1.f);
  std::vector<Float3> points(1000);  // not a multiple of the work-group size
  for (Float3& p : points) p = {unit(rng), unit(rng), unit(rng)};
  KMeansCpu cpu;
  KMeansVk gpu(context);
  cpu.set_points(points);
  gpu.set_points(points);
  const std::vector<Eigen::Vector3f> centres{{0.2f, 0.2f, 0.2f}, {0.8f, 0.5f, 0.1f}, {0.5f, 0.5f, 0.9f}};
  const ClusterSums a = cpu.step(centres), b = gpu.step(centres);
  for (std::size_t k = 0; k < centres.size(); ++k) {
    EXPECT_EQ(a.clusters[k].count, b.clusters[k].count) << k;
    EXPECT_EQ(a.clusters[k].distance, b.clusters[k].distance) << k;
    for (int c = 0; c < 3; ++c) EXPECT_EQ(a.clusters[k].sum[c], b.clusters[k].sum[c]) << k;
  }
  std::vector<std::uint8_t> la, lb;
  cpu.read_labels(la);
  gpu.read_labels(lb);
  EXPECT_EQ(la, lb);
}

TEST_F(KMeansVkTest, SameInitialCentresGiveTheSameClusteringOnTheSyntheticScene) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  const std::vector<Float3> points = scene_kd_points();
  KMeansCpu cpu;
  KMeansVk gpu(context);
  cpu.set_points(points);
  gpu.set_points(points);
  std::mt19937_64 rng(9);
  for (int attempt = 0; attempt < 2; ++attempt) {
    const auto seeds = kmeans_pp_centres(points, 6, rng);
    const KMeansResult a = lloyd(cpu, seeds, {});
    const KMeansResult b = lloyd(gpu, seeds, {});
    EXPECT_EQ(a.labels, b.labels);
    EXPECT_EQ(a.centres, b.centres);
    EXPECT_EQ(a.compactness, b.compactness);
    EXPECT_EQ(a.iterations, b.iterations);
    EXPECT_GT(a.iterations, 1);
  }
  EXPECT_TRUE(gpu.gpu_ms().has_value());
}

}  // namespace
}  // namespace relight::brdf
