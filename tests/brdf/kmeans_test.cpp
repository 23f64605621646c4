// K-means (kmeans.h): exact sums, determinism across thread counts, the warm-start policy, and on
// the synthetic scene the cluster map against the ground-truth materials (adjusted Rand index)
// and the cluster centres against the true albedos.
#include "relight/brdf/kmeans.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <map>
#include <random>

#include "brdf_test_scene.h"
#include "relight/brdf/diffuse.h"
#include "relight/brdf/highlight.h"

namespace relight::brdf {
namespace {

struct SceneClusters {
  std::vector<Float3> points;
  std::vector<int> truth;        ///< albedo class per point
  std::vector<Float3> albedo;    ///< true k_d per point
  std::vector<std::uint8_t> lit; ///< 1 where no light is shadowed
  std::size_t clustered = 0;     ///< the first points, marked 1 by the diffuse stage (the rest 2)
};

// Materials with the same albedo (floor/table wood, wall/tag white) cannot be told apart from
// k_d, so the ground truth is the albedo class: the first material index with that albedo.
int albedo_class(const synth::Scene& scene, int id) {
  const Eigen::Vector3d kd = scene.materials[static_cast<std::size_t>(id - 1)].kd;
  for (std::size_t m = 0; m < scene.materials.size(); ++m) {
    if (scene.materials[m].kd == kd) return static_cast<int>(m);
  }
  return -1;
}

// `lit_only`: drop pixels where a light is shadowed. Shadows are not modelled (diffuse.h), so a
// shadowed pixel's k_d is too dark and forms clusters of its own; the lit-only input measures the
// clustering itself, the full input measures what the shadow limitation costs.
SceneClusters scene_points(const ColorImage& color, bool lit_only = false) {
  const test::BrdfScene& s = test::brdf_scene();
  ColorImage cleaned;
  Mask highlights, valid;
  remove_highlights(color, {}, cleaned, highlights);
  RadianceImage kd;
  estimate_diffuse(cleaned, s.positions, s.truth.normals, s.lights, {}, kd, valid);
  SceneClusters out;
  // In the order of gather_points(): the pixels K-means clusters, then those it only assigns.
  for (const std::uint8_t mark : {std::uint8_t{1}, std::uint8_t{2}}) {
    for (std::size_t i = 0; i < kd.size(); ++i) {
      if (valid.pixels()[i] != mark || (lit_only && s.shadowed.pixels()[i])) continue;
      out.points.push_back(kmeans_feature(kd.pixels()[i]));
      out.truth.push_back(albedo_class(s.scene, s.truth.material.pixels()[i]));
      out.albedo.push_back(s.truth.albedo.pixels()[i]);
      out.lit.push_back(s.shadowed.pixels()[i] ? 0 : 1);
    }
    if (mark == 1) out.clustered = out.points.size();
  }
  return out;
}

std::vector<int> as_int(const std::vector<std::uint8_t>& labels) { return {labels.begin(), labels.end()}; }

TEST(KMeans, AdjustedRandIndexOfKnownLabelings) {
  const std::vector<int> a{0, 0, 1, 1, 2, 2};
  const std::vector<int> renamed{5, 5, 3, 3, 9, 9};
  EXPECT_DOUBLE_EQ(adjusted_rand_index(a, renamed), 1.0);
  const std::vector<int> b{0, 0, 1, 2, 2, 2};
  // Contingency {2,1,1,2}: index 2, row/col pair sums 3 and 4, 15 pairs: (2 - 0.8) / (3.5 - 0.8).
  EXPECT_NEAR(adjusted_rand_index(a, b), 1.2 / 2.7, 1e-12);
}

TEST(KMeans, SeparatedBlobsAreFoundAndSumsAreExact) {
  std::mt19937_64 rng(3);
  std::normal_distribution<float> noise(0.f, 0.01f);
  const Float3 blobs[3] = {{0.1f, 0.1f, 0.1f}, {0.8f, 0.2f, 0.1f}, {0.2f, 0.3f, 0.9f}};
  std::vector<Float3> points;
  std::vector<int> truth;
  for (int i = 0; i < 3000; ++i) {
    const Float3 b = blobs[i % 3];
    points.push_back(kmeans_feature({b.x + noise(rng), b.y + noise(rng), b.z + noise(rng)}));
    truth.push_back(i % 3);
  }
  KMeansCpu cpu;
  KMeansOptions options;
  options.clusters = 3;
  const KMeansResult r = kmeans(cpu, points, options, 3, rng);
  EXPECT_TRUE(r.converged);
  EXPECT_DOUBLE_EQ(adjusted_rand_index(as_int(r.labels), truth), 1.0);
  // Compactness equals the sum of squared distances to the centres that made the assignment,
  // to the fixed-point resolution (half a unit of 2^-20 per point).
  EXPECT_NEAR(r.compactness, 3000 * 3 * 0.01 * 0.01, 0.1 * 3000 * 3 * 0.01 * 0.01);
}

TEST(KMeans, ResultDoesNotDependOnTheThreadCount) {
  const SceneClusters data = scene_points(test::brdf_scene().color);
  KMeansCpu one(1), two(2);
  one.set_points(data.points);
  two.set_points(data.points);
  std::mt19937_64 rng(7);
  const auto seeds = kmeans_pp_centres(data.points, 6, rng);
  const KMeansResult a = lloyd(one, seeds, {});
  const KMeansResult b = lloyd(two, seeds, {});
  EXPECT_EQ(a.labels, b.labels);
  EXPECT_EQ(a.centres, b.centres);
  EXPECT_EQ(a.compactness, b.compactness);
  EXPECT_EQ(a.iterations, b.iterations);
}

TEST(KMeans, VectorisedAndPortableStepsAgreeExactly) {
  // Random points (a count that leaves a tail after the groups of eight), plus points exactly
  // halfway between two centres: both builds must break those ties towards the lower index.
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<float> unit(0.f, 2.f);
  std::vector<Float3> points;
  for (int i = 0; i < 10007; ++i) points.push_back({unit(rng), unit(rng), unit(rng)});
  for (int i = 0; i < 64; ++i) points.push_back({0.5f, 0.25f * static_cast<float>(i % 8), 1.f});
  for (const int clusters : {1, 6, 16}) {
    std::vector<Eigen::Vector3f> centres = kmeans_pp_centres(points, clusters, rng);
    if (clusters >= 2) {
      centres[0] = {0.25f, 1.f, 1.f};  // the halfway points are 0.25 + 0.5 * (y - 1)^2 from both
      centres[1] = {0.75f, 1.f, 1.f};
    }
    KMeansCpu fastest(2, KMeansCpuKernel::Fastest), portable(2, KMeansCpuKernel::Portable);
    fastest.set_points(points);
    portable.set_points(points);
    const ClusterSums a = fastest.step(centres), b = portable.step(centres);
    std::vector<std::uint8_t> la, lb;
    fastest.read_labels(la);
    portable.read_labels(lb);
    EXPECT_EQ(la, lb) << clusters;
    ASSERT_EQ(a.clusters.size(), b.clusters.size());
    for (std::size_t k = 0; k < a.clusters.size(); ++k) {
      for (int c = 0; c < 3; ++c) EXPECT_EQ(a.clusters[k].sum[c], b.clusters[k].sum[c]) << clusters << " " << k;
      EXPECT_EQ(a.clusters[k].count, b.clusters[k].count) << clusters << " " << k;
      EXPECT_EQ(a.clusters[k].distance, b.clusters[k].distance) << clusters << " " << k;
    }
    if (clusters >= 2) {
      // The tie points all went to centre 0, and none of them is nearer to centre 1.
      for (std::size_t i = 10007; i < points.size(); ++i) EXPECT_NE(la[i], 1) << i;
    }
  }
}

TEST(KMeans, UseFirstStepsOnAPrefixAsIfOnlyItWasSet) {
  const SceneClusters data = scene_points(test::brdf_scene().color);
  const std::size_t prefix = data.points.size() / 3;
  std::mt19937_64 rng(5);
  const auto centres = kmeans_pp_centres(data.points, 6, rng);
  KMeansCpu all, only;
  all.set_points(data.points);
  all.use_first(prefix);
  only.set_points(std::span<const Float3>(data.points).first(prefix));
  const ClusterSums a = all.step(centres), b = only.step(centres);
  std::vector<std::uint8_t> la, lb;
  all.read_labels(la);
  only.read_labels(lb);
  EXPECT_EQ(la, lb);
  ASSERT_EQ(a.clusters.size(), b.clusters.size());
  for (std::size_t k = 0; k < a.clusters.size(); ++k) {
    EXPECT_EQ(a.clusters[k].count, b.clusters[k].count);
    EXPECT_EQ(a.clusters[k].distance, b.clusters[k].distance);
  }
  all.use_first(data.points.size());
  EXPECT_GT(all.step(centres).total_variance(), a.total_variance());
}

TEST(KMeans, SyntheticClusterMapMatchesTheMaterialsAndCentresTheAlbedos) {
  const SceneClusters data = scene_points(test::brdf_scene().color, true);
  KMeansCpu cpu;
  KMeansTracker tracker;
  const KMeansResult r = tracker.run(cpu, data.points, data.clustered);
  EXPECT_FALSE(tracker.last_used_warm_start());
  EXPECT_TRUE(tracker.last_ran_random());
  const double ari = adjusted_rand_index(as_int(r.labels), data.truth);
  std::printf("kmeans: %zu points (%zu clustered), ARI %.4f, %d iterations, compactness %.3f\n", data.points.size(),
              data.clustered, ari, r.iterations, r.compactness);
  // Issue goal 0.9; measured 0.950. Without leaving the pixels inside the lights' mirror cones
  // out of the clustering (diffuse.h) and separating merged centres (kmeans.h) it was 0.885:
  // the table's sheen (k_s 0.15, n 20) took a cluster of its own and the yellow object had none.
  EXPECT_GE(ari, 0.9);
  EXPECT_LT(data.clustered, data.points.size());
  int accurate = 0;
  // Each cluster's centre against the albedo of its majority class, over directly lit pixels.
  for (std::size_t k = 0; k < r.centres.size(); ++k) {
    std::map<int, int> votes;
    for (std::size_t i = 0; i < data.points.size(); ++i) {
      if (r.labels[i] == k && data.lit[i]) ++votes[data.truth[i]];
    }
    if (votes.empty()) continue;
    const auto majority = std::max_element(votes.begin(), votes.end(),
                                           [](const auto& x, const auto& y) { return x.second < y.second; });
    const Eigen::Vector3d truth = test::brdf_scene().scene.materials[static_cast<std::size_t>(majority->first)].kd;
    const double error = (r.centres[k].cast<double>() - truth).cwiseAbs().maxCoeff();
    accurate += error <= 0.03;
    std::printf("  cluster %zu: centre (%.3f %.3f %.3f), %s, error %.4f\n", k, r.centres[k].x(), r.centres[k].y(),
                r.centres[k].z(), test::brdf_scene().scene.materials[static_cast<std::size_t>(majority->first)].name.c_str(),
                error);
  }
  EXPECT_EQ(accurate, 6);  // measured: every centre within 0.003 of its albedo
  // Frame 2 starts warm; frame 5 (index 5) runs from seeds as well.
  (void)tracker.run(cpu, data.points, data.clustered);
  EXPECT_TRUE(tracker.last_used_warm_start());
  EXPECT_FALSE(tracker.last_ran_random());
  for (int f = 2; f < 5; ++f) (void)tracker.run(cpu, data.points, data.clustered);
  const KMeansResult fifth = tracker.run(cpu, data.points, data.clustered);
  EXPECT_TRUE(tracker.last_used_warm_start());
  EXPECT_TRUE(tracker.last_ran_random());
  EXPECT_LE(fifth.compactness, r.compactness * (1 + 1e-9));
}

TEST(KMeans, ReportsTheAdjustedRandIndexWithColourNoise) {
  ColorImage noisy = test::brdf_scene().color;
  std::mt19937_64 rng(11);
  std::normal_distribution<float> noise(0.f, 2.f);  // 8-bit levels, a camera's shot/read noise
  auto add = [&](std::uint8_t v) { return static_cast<std::uint8_t>(std::clamp(v + std::lround(noise(rng)), 0L, 255L)); };
  for (Rgb8& p : noisy.pixels()) p = {add(p.r), add(p.g), add(p.b)};
  const SceneClusters data = scene_points(noisy, true);
  KMeansCpu cpu;
  KMeansTracker tracker;
  const KMeansResult r = tracker.run(cpu, data.points, data.clustered);
  const double ari = adjusted_rand_index(as_int(r.labels), data.truth);
  std::printf("kmeans: colour noise sigma 2/255: ARI %.4f\n", ari);
  EXPECT_GE(ari, 0.9);  // measured 0.950
}

TEST(KMeans, ReportsTheAdjustedRandIndexWithShadows) {
  const SceneClusters data = scene_points(test::brdf_scene().color);
  KMeansCpu cpu;
  KMeansTracker tracker;
  const KMeansResult r = tracker.run(cpu, data.points, data.clustered);
  const double ari = adjusted_rand_index(as_int(r.labels), data.truth);
  std::printf("kmeans: shadowed pixels included: ARI %.4f\n", ari);
  EXPECT_GE(ari, 0.65);  // measured 0.731
}

}  // namespace
}  // namespace relight::brdf
