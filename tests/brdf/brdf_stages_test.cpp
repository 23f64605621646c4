// The BRDF stages in a frame graph over the synthetic scene: the Materials slot is complete and
// consistent, the CPU and Vulkan K-means stages give identical materials, the matte wall's
// cluster is diffuse and the glossy sphere's k_s and n come out within 10 %.
#include "relight/brdf/brdf_stages.h"

#include <gtest/gtest.h>

#include <map>

#include "brdf_test_scene.h"
#include "relight/brdf/brdf_preview.h"
#include "relight/vk/transfer.h"
#include "support/vulkan_test_env.h"

namespace relight::brdf {
namespace {

/// Writes the synthetic view as the reconstruction and light stages would: colour, exact
/// positions and normals, the exact light set and the camera pose; `frames` frames.
class SceneSource final : public Stage {
 public:
  explicit SceneSource(int frames) : frames_(frames) {}
  [[nodiscard]] std::string name() const override { return "source"; }
  [[nodiscard]] bool has_side_effects() const override { return true; }
  void declare(StageBuilder& b) override {
    color_ = b.write<ColorImage>("color");
    positions_ = b.write<PositionMap>("positions");
    normals_ = b.write<NormalMap>("normals");
    lights_ = b.write<lights::LightSet>("lights");
    frame_ = b.write<FrameInfo>("frame");
  }
  void run(StageContext& ctx) override {
    if (ctx.frame_index() >= frames_) return ctx.end_of_stream();
    const test::BrdfScene& s = test::brdf_scene();
    ctx.get(color_) = s.color;
    ctx.get(positions_) = s.positions;
    ctx.get(normals_) = s.truth.normals;
    ctx.get(lights_) = test::light_set_of(s.scene);
    ctx.get(frame_) = FrameInfo{ctx.frame_index(), 0.0, s.camera_to_world, s.intrinsics};
  }

 private:
  int frames_;
  Write<ColorImage> color_;
  Write<PositionMap> positions_;
  Write<NormalMap> normals_;
  Write<lights::LightSet> lights_;
  Write<FrameInfo> frame_;
};

// Fewer samples and fixed lights keep the debug-build test fast; the solvers' own tests cover
// moving lights and the full sample budget.
BrdfOptions scene_options() {
  BrdfOptions options;
  options.ambient = test::brdf_scene().scene.environment.cast<float>();
  options.max_samples = 512;
  options.specular.moving_lights = 0;
  return options;
}

Materials run_graph(Backend backend, vk::VulkanContext* context, int frames = 1) {
  FrameGraph graph(context ? &context->transfer() : nullptr);
  graph.emplace<SceneSource>(frames);
  add_brdf_stages(graph, scene_options(), backend, context);
  graph.keep("materials");
  graph.compile();
  for (int f = 0; f < frames; ++f) EXPECT_TRUE(graph.run_frame());
  const Materials* m = graph.find<Materials>("materials");
  EXPECT_NE(m, nullptr);
  return m ? *m : Materials{};
}

int majority_cluster(const Materials& m, int material_id) {
  const test::BrdfScene& s = test::brdf_scene();
  std::map<int, int> votes;
  for (std::size_t i = 0; i < m.ids.size(); ++i) {
    if (s.truth.material.pixels()[i] == material_id && m.ids.pixels()[i] != 0) ++votes[m.ids.pixels()[i] - 1];
  }
  return std::max_element(votes.begin(), votes.end(), [](auto& a, auto& b) { return a.second < b.second; })->first;
}

TEST(BrdfStages, GraphProducesConsistentMaterials) {
  const Materials m = run_graph(Backend::Cpu, nullptr);
  const test::BrdfScene& s = test::brdf_scene();
  ASSERT_EQ(m.clusters.size(), 6u);
  ASSERT_TRUE(m.ids.same_shape(s.color));
  int labelled = 0;
  for (const auto id : m.ids.pixels()) {
    ASSERT_LE(id, 6);
    labelled += id != 0;
  }
  int counted = 0;
  for (const MaterialParams& c : m.clusters) counted += c.pixels;
  EXPECT_EQ(labelled, counted);
  EXPECT_GT(labelled, 0.9 * static_cast<double>(m.ids.size()));
  const MaterialParams& wall = m.clusters[static_cast<std::size_t>(majority_cluster(m, test::material_id(s.scene, "wall")))];
  EXPECT_NEAR(wall.kd.x(), 0.70f, 0.03f);
  EXPECT_LT(wall.ks, 0.02f);
  // End to end (highlight removal, k_d, K-means, fit) the glossy sphere keeps its own cluster.
  const MaterialParams& blue =
      m.clusters[static_cast<std::size_t>(majority_cluster(m, test::material_id(s.scene, "glossy_blue")))];
  EXPECT_LT((blue.kd - Eigen::Vector3f(0.10f, 0.18f, 0.60f)).cwiseAbs().maxCoeff(), 0.03f);
  EXPECT_NEAR(blue.ks, 0.6f, 0.06f);
  EXPECT_NEAR(blue.n, 80.f, 8.f);
  for (const MaterialParams& c : m.clusters) {
    std::printf("cluster kd (%.3f %.3f %.3f) ks %.3f n %.1f rms %.4f pixels %d\n", c.kd.x(), c.kd.y(), c.kd.z(), c.ks,
                c.n, c.fit_rms, c.pixels);
  }
}

class BrdfStagesVkTest : public test::VulkanTest {};

TEST_F(BrdfStagesVkTest, VulkanBackendGivesTheSameMaterials) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  const Materials cpu = run_graph(Backend::Cpu, nullptr, 2);  // the second frame starts warm
  const Materials gpu = run_graph(Backend::Vulkan, &context, 2);
  ASSERT_EQ(cpu.clusters.size(), gpu.clusters.size());
  // K-means: identical (exact integer sums on both).
  EXPECT_EQ(cpu.ids, gpu.ids);
  for (std::size_t k = 0; k < cpu.clusters.size(); ++k) {
    const MaterialParams &a = cpu.clusters[k], &b = gpu.clusters[k];
    EXPECT_EQ(a.kd, b.kd);
    // The specular fits start from different grids (CPU: 12 exponents with least-squares k_s;
    // GPU: 24 x 16 (n, k_s)) and must reach the same optimum.
    EXPECT_EQ(a.ks > 0.f, b.ks > 0.f) << k;
    if (a.ks > 0.f && b.ks > 0.f) {
      EXPECT_NEAR(b.ks, a.ks, 0.02f * a.ks) << k;
      EXPECT_NEAR(b.n, a.n, 0.05f * a.n) << k;
      std::printf("cluster %zu: CPU start ks %.4f n %.2f, GPU start ks %.4f n %.2f\n", k, a.ks, a.n, b.ks, b.n);
    }
  }
}

// A run that writes no frames makes the preview only for the frames its report shows: the other
// frames get an empty picture, the wanted one the full five-panel mosaic.
TEST(BrdfStages, ThePreviewIsMadeOnlyForTheWantedFrames) {
  FrameGraph graph;
  graph.emplace<SceneSource>(3);
  add_brdf_stages(graph, scene_options(), Backend::Cpu, nullptr);
  graph.emplace<BrdfPreviewStage>().only_for([](std::int64_t frame) { return frame == 1; });
  graph.keep(kBrdfPreview);
  graph.compile();
  const ColorImage& color = test::brdf_scene().color;
  for (std::int64_t frame = 0; frame < 3; ++frame) {
    ASSERT_TRUE(graph.run_frame());
    const ColorImage* preview = graph.find(kBrdfPreview);
    ASSERT_NE(preview, nullptr);
    if (frame == 1) {
      EXPECT_EQ(preview->width(), 5 * color.width());
      EXPECT_EQ(preview->height(), color.height());
    } else {
      EXPECT_TRUE(preview->pixels().empty()) << "frame " << frame;
    }
  }
}

TEST(BrdfStages, ReRenderReproducesTheCameraOnMatteSurfaces) {
  const test::BrdfScene& s = test::brdf_scene();
  const Materials m = run_graph(Backend::Cpu, nullptr);
  const RadianceImage rerender = render_materials(m, s.positions, s.truth.normals, s.lights);
  const int wall = test::material_id(s.scene, "wall");
  double worst = 0.0;
  for (std::size_t i = 0; i < rerender.size(); ++i) {
    if (s.truth.material.pixels()[i] != wall || m.ids.pixels()[i] == 0) continue;
    const Float3 e = rerender.pixels()[i] - s.truth.radiance.pixels()[i];
    worst = std::max<double>(worst, std::max({std::abs(e.x), std::abs(e.y), std::abs(e.z)}));
  }
  EXPECT_LT(worst, 0.03);
}

}  // namespace
}  // namespace relight::brdf
