// The colour-mapping stages in a frame graph: buffer wiring, CPU and Vulkan statistics stages
// agree, the sample stage smooths across frames, the composite reaches the colour goal, and a
// size mismatch is a clear error.
#include "relight/colormap/colormap_stages.h"

#include <gtest/gtest.h>

#include "colormap_test_scene.h"
#include "support/vulkan_test_env.h"
#include "relight/core/error.h"
#include "relight/vk/transfer.h"

namespace relight::colormap {
namespace {

// Writes a synthetic triple into "L_r", "L_rv" and "color" every frame.
class TripleSource final : public Stage {
 public:
  explicit TripleSource(const truth::SyntheticTriple& triple, bool wrong_camera_size = false)
      : triple_(triple), wrong_camera_size_(wrong_camera_size) {}
  [[nodiscard]] std::string name() const override { return "triple_source"; }
  [[nodiscard]] bool has_side_effects() const override { return true; }
  void declare(StageBuilder& builder) override {
    real_ = builder.write<RadianceImage>("L_r");
    real_virtual_ = builder.write<RadianceImage>("L_rv");
    camera_ = builder.write<ColorImage>("color");
  }
  void run(StageContext& context) override {
    context.get(real_) = triple_.real;
    context.get(real_virtual_) = triple_.real_virtual;
    context.get(camera_) = wrong_camera_size_ ? ColorImage(8, 8) : triple_.camera;
  }

 private:
  const truth::SyntheticTriple& triple_;
  bool wrong_camera_size_;
  Write<RadianceImage> real_, real_virtual_;
  Write<ColorImage> camera_;
};

ColorImage run_graph(ColorMapMethod method, Backend backend, vk::VulkanContext* context, int frames = 1) {
  FrameGraph graph(context ? &context->transfer() : nullptr);
  graph.emplace<TripleSource>(test::orange_triple());
  graph.add(make_color_map_stage(method, backend, context));
  graph.emplace<ColorMapCompositeStage>();
  graph.keep("color_mapped");
  graph.compile();
  for (int i = 0; i < frames; ++i) EXPECT_TRUE(graph.run_frame());
  const ColorImage* mapped = graph.find<ColorImage>("color_mapped");
  if (!mapped) throw LogicError("color_mapped was not written");
  return *mapped;
}

double graph_delta_e(const ColorImage& mapped) {
  const auto& triple = test::orange_triple();
  return truth::mean_delta_e(mapped, triple.truth, virtual_mask(triple.real, triple.real_virtual));
}

TEST(ColorMapStages, EveryMethodRunsInAGraphAndMappingBeatsNone) {
  const double none = graph_delta_e(run_graph(ColorMapMethod::None, Backend::Cpu, nullptr));
  const double statistics = graph_delta_e(run_graph(ColorMapMethod::Statistics, Backend::Cpu, nullptr));
  const double sample = graph_delta_e(run_graph(ColorMapMethod::Sample, Backend::Cpu, nullptr, 3));
  EXPECT_GT(none, 6.0);
  EXPECT_LT(statistics, 3.0);  // orange sphere: 2.66 measured
  EXPECT_LT(sample, 3.0);
}

// The ColorMapping buffer is the tau the stage used: tau(L_rv) - tau(L_r) reproduces delta_L.
void expect_mapping_reproduces_delta(ColorMapMethod method, Backend backend, vk::VulkanContext* context) {
  const auto& triple = test::orange_triple();
  FrameGraph graph(context ? &context->transfer() : nullptr);
  graph.emplace<TripleSource>(triple);
  graph.add(make_color_map_stage(method, backend, context));
  graph.keep("delta_L");
  graph.keep("color_mapping");
  graph.compile();
  ASSERT_TRUE(graph.run_frame());
  const auto* delta = graph.find<RadianceImage>("delta_L");
  const auto* mapping = graph.find<ColorMapping>("color_mapping");
  ASSERT_TRUE(delta && mapping);
  int checked = 0;
  for (std::size_t i = 0; i < delta->size(); ++i) {
    const Float3& r = triple.real.pixels()[i];
    const Float3& rv = triple.real_virtual.pixels()[i];
    if (r == rv) continue;
    const Float3 expected = (*mapping)(rv) - (*mapping)(r);
    const Float3& actual = delta->pixels()[i];
    // The stages' Lab conversion uses a fast cube root (about 1e-4 relative).
    ASSERT_NEAR(actual.x, expected.x, 2e-3) << i;
    ASSERT_NEAR(actual.y, expected.y, 2e-3) << i;
    ASSERT_NEAR(actual.z, expected.z, 2e-3) << i;
    ++checked;
  }
  EXPECT_GT(checked, 200);
}

TEST(ColorMapStages, EveryStageWritesTheMappingItApplied) {
  expect_mapping_reproduces_delta(ColorMapMethod::None, Backend::Cpu, nullptr);
  expect_mapping_reproduces_delta(ColorMapMethod::Statistics, Backend::Cpu, nullptr);
  expect_mapping_reproduces_delta(ColorMapMethod::Sample, Backend::Cpu, nullptr);
}

TEST(ColorMapStages, StagesDeclareTheDocumentedBuffers) {
  FrameGraph graph;
  graph.emplace<TripleSource>(test::orange_triple());
  graph.emplace<StatisticsColorMapCpuStage>();
  graph.emplace<ColorMapCompositeStage>();
  graph.keep("color_mapped");
  graph.keep("color_mapping");
  graph.compile();
  const std::string dot = graph.to_dot();
  for (const char* buffer : {"L_r", "L_rv", "color", "delta_L", "color_mapping", "color_mapped"}) {
    EXPECT_NE(dot.find(buffer), std::string::npos) << buffer;
  }
}

TEST(ColorMapStages, SizeMismatchIsAClearError) {
  FrameGraph graph;
  graph.emplace<TripleSource>(test::orange_triple(), true);
  graph.emplace<StatisticsColorMapCpuStage>();
  graph.keep("delta_L");
  graph.compile();
  try {
    (void)graph.run_frame();
    FAIL() << "expected relight::Error";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("same size"), std::string::npos) << error.what();
  }
}

class ColorMapStagesVulkan : public ::relight::test::VulkanTest {};

TEST_F(ColorMapStagesVulkan, VulkanStatisticsStageMatchesTheCpuStage) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  const ColorImage cpu = run_graph(ColorMapMethod::Statistics, Backend::Cpu, nullptr);
  const ColorImage gpu = run_graph(ColorMapMethod::Statistics, Backend::Vulkan, &context, 2);
  ASSERT_TRUE(cpu.same_shape(gpu));
  int differing = 0, worst = 0;
  for (std::size_t i = 0; i < cpu.size(); ++i) {
    const Rgb8 a = cpu.pixels()[i], b = gpu.pixels()[i];
    const int d = std::max({std::abs(a.r - b.r), std::abs(a.g - b.g), std::abs(a.b - b.b)});
    worst = std::max(worst, d);
    differing += d > 0 ? 1 : 0;
  }
  EXPECT_LE(worst, 1);  // float rounding may flip an 8-bit rounding boundary, nothing more
  EXPECT_LT(differing, static_cast<int>(cpu.size()) / 100);
}

TEST_F(ColorMapStagesVulkan, VulkanStatisticsStageWritesTheMappingItApplied) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  expect_mapping_reproduces_delta(ColorMapMethod::Statistics, Backend::Vulkan, &context);
}

}  // namespace
}  // namespace relight::colormap
