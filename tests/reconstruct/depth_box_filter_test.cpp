// The depth box filter: hand-computed cases and a 640x480 synthetic depth with holes, for every
// backend (Open3D's PermuteDevices pattern), plus the frame-graph stages on both backends.
#include "relight/reconstruct/depth_box_filter.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "relight/vk/context.h"
#include "relight/vk/transfer.h"
#include "support/vulkan_test_env.h"

namespace relight::reconstruct {

// Readable parameter values in test output ("Vulkan", not "4-byte object <01-00 00-00>").
void PrintTo(Backend backend, std::ostream* out) { *out << to_string(backend); }

namespace {

constexpr float kNan = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

DepthMap make_depth(int width, int height, std::initializer_list<float> values) {
  DepthMap depth(width, height);
  std::copy(values.begin(), values.end(), depth.pixels().begin());
  return depth;
}

// 640x480: a smooth surface 0.6..3.9 m with noise, 10 % random holes, a rectangular hole, and a
// few NaN/inf/negative values (all invalid), as a depth camera delivers them.
DepthMap synthetic_depth(int width = 640, int height = 480) {
  DepthMap depth(width, height);
  std::mt19937 random(42);
  std::uniform_real_distribution<float> noise(-0.01f, 0.01f);
  std::uniform_int_distribution<int> percent(0, 99);
  for (int r = 0; r < height; ++r) {
    for (int c = 0; c < width; ++c) {
      float d = 2.2f + 1.2f * std::sin(0.031f * static_cast<float>(c)) * std::cos(0.017f * static_cast<float>(r)) +
                noise(random);
      const int roll = percent(random);
      if (roll < 10) d = 0.f;
      if (roll == 10) d = kNan;
      if (roll == 11 && c % 2 == 0) d = kInf;
      if (roll == 11 && c % 2 == 1) d = -1.f;
      if (r >= 100 && r < 140 && c >= 200 && c < 260) d = 0.f;
      depth(r, c) = d;
    }
  }
  return depth;
}

float max_abs_diff(const DepthMap& a, const DepthMap& b) {
  float worst = 0.f;
  for (std::size_t i = 0; i < a.size(); ++i) worst = std::max(worst, std::fabs(a.pixels()[i] - b.pixels()[i]));
  return worst;
}

class DepthBoxFilterPermuteBackends : public test::VulkanTest, public ::testing::WithParamInterface<Backend> {
 protected:
  // Filters with the backend under test; Vulkan uses the shared context.
  DepthMap filter(const DepthMap& depth) {
    if (GetParam() == Backend::Cpu) return depth_box_filter(depth);
    DepthBoxFilterVk vulkan(*test::shared_vulkan().context);
    return vulkan.run(depth);
  }
};

// Skips/fails the Vulkan instance when there is no device; the Cpu instance always runs.
#define RELIGHT_BACKEND_AVAILABLE()                       \
  if (GetParam() == Backend::Vulkan) {                    \
    RELIGHT_REQUIRE_VULKAN_CONTEXT(vulkan_context_check); \
    (void)vulkan_context_check;                           \
  }

TEST_P(DepthBoxFilterPermuteBackends, HandComputed3x3WithInvalidCentre) {
  RELIGHT_BACKEND_AVAILABLE();
  const DepthMap depth = make_depth(3, 3, {1, 2, 3,  //
                                           4, 0, 6,  //
                                           7, 8, 9});
  const DepthMap out = filter(depth);
  ASSERT_TRUE(out.same_shape(depth));
  // Corners average 4 window pixels, edges 6; the invalid centre is skipped and stays 0.
  const float expected[3][3] = {{7.f / 3, 16.f / 5, 11.f / 3}, {22.f / 5, 0.f, 28.f / 5}, {19.f / 3, 34.f / 5, 23.f / 3}};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(out(r, c), expected[r][c]) << "at (" << r << ", " << c << ")";
  }
}

TEST_P(DepthBoxFilterPermuteBackends, NonFiniteAndNegativeDepthCountAsMissing) {
  RELIGHT_BACKEND_AVAILABLE();
  const DepthMap out = filter(make_depth(6, 1, {1, kNan, 3, -1, 2, kInf}));
  const std::vector<float> expected = {1.f, 0.f, 3.f, 0.f, 2.f, 0.f};
  EXPECT_EQ(std::vector<float>(out.pixels().begin(), out.pixels().end()), expected);
}

TEST_P(DepthBoxFilterPermuteBackends, ColumnImageAndBorders) {
  RELIGHT_BACKEND_AVAILABLE();
  const DepthMap out = filter(make_depth(1, 4, {1, 2, 0, 4}));
  EXPECT_FLOAT_EQ(out(0, 0), 1.5f);  // {1, 2}
  EXPECT_FLOAT_EQ(out(1, 0), 1.5f);  // {1, 2, 0}
  EXPECT_FLOAT_EQ(out(2, 0), 0.f);   // invalid centre
  EXPECT_FLOAT_EQ(out(3, 0), 4.f);   // {0, 4}
}

TEST_P(DepthBoxFilterPermuteBackends, SinglePixelAndEmptyImages) {
  RELIGHT_BACKEND_AVAILABLE();
  EXPECT_FLOAT_EQ(filter(make_depth(1, 1, {2.5f}))(0, 0), 2.5f);
  EXPECT_FLOAT_EQ(filter(make_depth(1, 1, {0.f}))(0, 0), 0.f);
  EXPECT_TRUE(filter(DepthMap()).empty());
}

TEST_P(DepthBoxFilterPermuteBackends, MatchesCpuReferenceOnSyntheticVgaDepthWithHoles) {
  RELIGHT_BACKEND_AVAILABLE();
  const DepthMap depth = synthetic_depth();
  const DepthMap reference = depth_box_filter(depth);
  const DepthMap out = filter(depth);
  ASSERT_TRUE(out.same_shape(depth));
  EXPECT_LE(max_abs_diff(out, reference), 1e-6f);
  // Holes stay holes and every output is finite.
  for (std::size_t i = 0; i < depth.size(); ++i) {
    ASSERT_TRUE(std::isfinite(out.pixels()[i])) << i;
    if (!is_valid_depth(depth.pixels()[i])) {
      ASSERT_EQ(out.pixels()[i], 0.f) << i;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Backends, DepthBoxFilterPermuteBackends, ::testing::Values(Backend::Cpu, Backend::Vulkan),
                         [](const auto& info) { return std::string(to_string(info.param)); });

// An independent oracle for the CPU reference: the definition evaluated in double.
TEST(DepthBoxFilterCpu, AgreesWithDoublePrecisionDefinition) {
  const DepthMap depth = synthetic_depth(97, 61);
  const DepthMap out = depth_box_filter(depth);
  for (int r = 0; r < depth.height(); ++r) {
    for (int c = 0; c < depth.width(); ++c) {
      if (!is_valid_depth(depth(r, c))) {
        ASSERT_EQ(out(r, c), 0.f);
        continue;
      }
      double sum = 0;
      int count = 0;
      for (int rr = r - 1; rr <= r + 1; ++rr) {
        for (int cc = c - 1; cc <= c + 1; ++cc) {
          if (depth.in_bounds(rr, cc) && is_valid_depth(depth(rr, cc))) {
            sum += depth(rr, cc);
            ++count;
          }
        }
      }
      ASSERT_NEAR(out(r, c), sum / count, 2e-6) << "at (" << r << ", " << c << ")";
    }
  }
}

TEST(DepthBoxFilterCpu, RejectsAliasedOutput) {
  DepthMap depth = make_depth(2, 1, {1, 2});
  EXPECT_THROW(depth_box_filter(depth, depth), LogicError);
}

// ---- Frame graph -------------------------------------------------------------------------

// Writes the synthetic depth (shifted a little per frame) on the host, as a camera source would.
class SyntheticDepthSource final : public Stage {
 public:
  explicit SyntheticDepthSource(int frames) : frames_(frames) {}
  std::string name() const override { return "source"; }
  bool has_side_effects() const override { return true; }
  void declare(StageBuilder& b) override { depth_ = b.write<DepthMap>("depth"); }
  void run(StageContext& ctx) override {
    if (ctx.frame_index() >= frames_) return ctx.end_of_stream();
    DepthMap& depth = ctx.get(depth_);
    depth = base_;
    for (float& d : depth.pixels()) {
      if (is_valid_depth(d)) d += 0.01f * static_cast<float>(ctx.frame_index());
    }
  }

 private:
  int frames_;
  DepthMap base_ = synthetic_depth();
  Write<DepthMap> depth_;
};

// A CPU stage after the filter: copies what it reads, forcing the graph to download.
class SmoothedReader final : public Stage {
 public:
  std::string name() const override { return "reader"; }
  bool has_side_effects() const override { return true; }
  void declare(StageBuilder& b) override { in_ = b.read<DepthMap>("depth_smoothed"); }
  void run(StageContext& ctx) override { seen.push_back(ctx.get(in_)); }
  std::vector<DepthMap> seen;

 private:
  Read<DepthMap> in_;
};

struct GraphRun {
  std::vector<DepthMap> seen;
  std::vector<double> device_ms;
};

GraphRun run_graph(Backend backend, vk::VulkanContext* context, int frames) {
  FrameGraph graph(context ? &context->transfer() : nullptr);
  graph.emplace<SyntheticDepthSource>(frames);
  graph.add(make_depth_box_filter_stage(backend, context));
  auto& reader = graph.emplace<SmoothedReader>();
  while (graph.run_frame()) {
  }
  GraphRun run{std::move(reader.seen), {}};
  for (const auto& timing : graph.timings()) {
    if (timing.stage == "depth_box_filter") run.device_ms = timing.device_ms;
  }
  return run;
}

using DepthBoxFilterGraph = test::VulkanTest;

TEST_F(DepthBoxFilterGraph, VulkanStageThenCpuReaderEqualsCpuGraph) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  const GraphRun cpu = run_graph(Backend::Cpu, nullptr, 3);
  const GraphRun vulkan = run_graph(Backend::Vulkan, &context, 3);
  ASSERT_EQ(cpu.seen.size(), 3u);
  ASSERT_EQ(vulkan.seen.size(), 3u);
  for (std::size_t frame = 0; frame < 3; ++frame) {
    ASSERT_TRUE(vulkan.seen[frame].same_shape(cpu.seen[frame]));
    EXPECT_LE(max_abs_diff(vulkan.seen[frame], cpu.seen[frame]), 1e-6f) << "frame " << frame;
  }
  EXPECT_TRUE(cpu.device_ms.empty());
  ASSERT_EQ(vulkan.device_ms.size(), 3u);  // GPU time from timestamp queries, every frame
  for (double ms : vulkan.device_ms) EXPECT_GT(ms, 0.0);
}

TEST(DepthBoxFilterGraphStaging, VulkanStageThroughStagingBuffersEqualsCpuGraph) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(shared);
  (void)shared;
  auto context = vk::try_create_vulkan({.validation = vk::Validation::On, .force_staging = true});
  ASSERT_NE(context, nullptr);
  const GraphRun cpu = run_graph(Backend::Cpu, nullptr, 2);
  const GraphRun vulkan = run_graph(Backend::Vulkan, context.get(), 2);
  ASSERT_EQ(vulkan.seen.size(), 2u);
  for (std::size_t frame = 0; frame < 2; ++frame) EXPECT_LE(max_abs_diff(vulkan.seen[frame], cpu.seen[frame]), 1e-6f);
  EXPECT_EQ(context->validation_errors(), 0) << context->validation_log()->summary();
}

TEST(DepthBoxFilterStageFactory, VulkanWithoutContextIsALogicError) {
  EXPECT_THROW((void)make_depth_box_filter_stage(Backend::Vulkan, nullptr), LogicError);
  EXPECT_EQ(make_depth_box_filter_stage(Backend::Cpu, nullptr)->backend(), Backend::Cpu);
}

}  // namespace
}  // namespace relight::reconstruct
