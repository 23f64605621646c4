// CrossNormalsVk (cross_normals_vk.h) against the CPU reference positions_from_depth +
// normals_from_positions: a noisy 320x240 synthetic frame at method 1's stride 4 and method 2's
// stride 1, hand-checkable planes with a step and a hole; method 1 with the GPU cross products
// finished on the CPU (normals_raw_depth_blend), NormalsRawDepthVk (all per-pixel passes on the
// GPU) and NormalsRawDepthVkStage in a frame graph, each against the CPU method 1 over three
// frames. Tolerance everywhere: same validity on >= 99.9 % of pixels, <= 0.5 degrees on >= 99 %
// of the normals, positions within 1 mm.
#include "relight/reconstruct/cross_normals_vk.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "relight/reconstruct/normals_from_positions.h"
#include "relight/reconstruct/normals_raw_depth.h"
#include "relight/reconstruct/normals_raw_depth_vk.h"
#include "relight/core/frame_graph.h"
#include "relight/vk/context.h"
#include "relight/vk/transfer.h"
#include "synthetic_sequence.h"
#include "support/vulkan_test_env.h"

namespace relight::reconstruct {
namespace {

// How far the Vulkan maps are from the CPU maps.
struct Agreement {
  double same_validity = 0;      ///< fraction of pixels where both or neither have a normal
  double within_half_degree = 0; ///< fraction of the pixels valid in both within 0.5 degrees
  double max_angle_deg = 0;      ///< over the pixels valid in both
  float max_position_diff_m = 0; ///< max |Δ| over all coordinates of all pixels
  std::size_t both_valid = 0;
};

Agreement compare(const PositionMap& cpu_positions, const NormalMap& cpu_normals, const PositionMap& vk_positions,
                  const NormalMap& vk_normals) {
  Agreement a;
  std::size_t same = 0, close = 0;
  for (std::size_t i = 0; i < cpu_normals.size(); ++i) {
    const Float3 p = cpu_positions.pixels()[i] - vk_positions.pixels()[i];
    a.max_position_diff_m = std::max({a.max_position_diff_m, std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)});
    const Float3& n = cpu_normals.pixels()[i];
    const Float3& m = vk_normals.pixels()[i];
    const bool cpu_valid = is_valid_normal(n), vk_valid = is_valid_normal(m);
    same += cpu_valid == vk_valid ? 1 : 0;
    if (!cpu_valid || !vk_valid) continue;
    ++a.both_valid;
    const double angle = std::acos(std::clamp(static_cast<double>(dot(n, m)), -1.0, 1.0)) * 180.0 / std::numbers::pi;
    a.max_angle_deg = std::max(a.max_angle_deg, angle);
    close += angle <= 0.5 ? 1 : 0;
  }
  a.same_validity = static_cast<double>(same) / static_cast<double>(cpu_normals.size());
  a.within_half_degree = a.both_valid ? static_cast<double>(close) / static_cast<double>(a.both_valid) : 1.0;
  return a;
}

void expect_agreement(const Agreement& a, const char* what) {
  std::printf("%s: same validity %.5f, within 0.5 deg %.5f (max %.4f deg), max position diff %.3g m, %zu normals\n",
              what, a.same_validity, a.within_half_degree, a.max_angle_deg, a.max_position_diff_m, a.both_valid);
  EXPECT_GE(a.same_validity, 0.999) << what;
  EXPECT_GE(a.within_half_degree, 0.99) << what;
  EXPECT_LE(a.max_position_diff_m, 1e-3f) << what;
}

using CrossNormalsVkTest = test::VulkanTest;

TEST_F(CrossNormalsVkTest, MatchesCpuReferenceOnNoisySyntheticFrame) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  const auto sequence = test::render_sequence(synth::Trajectory::Static, 1);  // 320x240, Kinect v1 noise
  const DepthMap& depth = sequence.frames.front().noisy;
  CrossNormalsVk gpu(context);
  for (const CrossNormalOptions options : {CrossNormalOptions{.stride = 4}, CrossNormalOptions{.stride = 4, .centred = true},
                                           CrossNormalOptions{.stride = 1}}) {
    const int stride = options.stride;
    PositionMap cpu_positions, vk_positions;
    NormalMap cpu_normals, vk_normals;
    positions_from_depth(depth, sequence.intrinsics, cpu_positions);
    normals_from_positions(cpu_positions, cpu_normals, options);
    gpu.run(depth, sequence.intrinsics, options, vk_positions, vk_normals);
    ASSERT_TRUE(vk_normals.same_shape(depth));
    ASSERT_TRUE(vk_positions.same_shape(depth));
    const Agreement a = compare(cpu_positions, cpu_normals, vk_positions, vk_normals);
    expect_agreement(a, (std::string("stride ") + std::to_string(stride) + (options.centred ? " centred" : "")).c_str());
    EXPECT_GT(a.both_valid, depth.size() / 2);  // the frame is mostly surface, not an empty comparison
  }
}

TEST_F(CrossNormalsVkTest, StepAndHoleFollowTheCpuRules) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  const PinholeIntrinsics k{.fx = 100, .fy = 100, .cx = 39.5, .cy = 29.5, .width = 80, .height = 60};
  DepthMap depth(k.width, k.height, 2.f);
  for (int r = 0; r < k.height; ++r) {
    for (int c = 40; c < k.width; ++c) depth(r, c) = 1.f;  // a 1 m step at column 40
  }
  depth(30, 10) = 0.f;
  depth(31, 10) = std::numeric_limits<float>::quiet_NaN();
  depth(40, 60) = std::numeric_limits<float>::infinity();
  PositionMap positions;
  NormalMap normals;
  CrossNormalsVk(context).run(depth, k, {.stride = 1}, positions, normals);
  EXPECT_NEAR(normals(20, 39).z, -1.f, 1e-5f);  // forward neighbour across the step: backward difference
  EXPECT_NEAR(normals(20, 40).z, -1.f, 1e-5f);
  EXPECT_FALSE(is_valid_normal(normals(30, 10)));  // no depth, no normal and no position
  EXPECT_FALSE(is_valid_normal(normals(31, 10)));
  EXPECT_FALSE(is_valid_normal(normals(40, 60)));
  EXPECT_EQ(positions(31, 10).z, 0.f);
  EXPECT_EQ(positions(40, 60).z, 0.f);
  EXPECT_NEAR(normals(30, 9).z, -1.f, 1e-5f);
  EXPECT_NEAR(positions(10, 20).x, (20 - k.cx) / k.fx * 2.0, 1e-6);
  // A single isolated pixel has no neighbour on either side: no normal.
  DepthMap lonely(5, 5, 0.f);
  lonely(2, 2) = 1.f;
  CrossNormalsVk(context).run(lonely, k, {.stride = 1}, positions, normals);
  EXPECT_FALSE(is_valid_normal(normals(2, 2)));
  EXPECT_EQ(positions(2, 2).z, 1.f);
}

TEST_F(CrossNormalsVkTest, RejectsBadStride) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  PositionMap positions;
  NormalMap normals;
  EXPECT_THROW(CrossNormalsVk(context).run(DepthMap(4, 4, 1.f), {}, {.stride = 0}, positions, normals), LogicError);
}

// Method 1 with the cross products on the GPU and the temporal blend on the CPU equals the CPU
// method 1 over three orbit frames (the blend amplifies no difference beyond the tolerance).
TEST_F(CrossNormalsVkTest, Method1WithGpuCrossProductsEqualsCpuOverThreeFrames) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  const auto sequence = test::render_sequence(synth::Trajectory::Orbit, 3);
  const NormalsRawDepthOptions options;
  CrossNormalsVk gpu(context);
  PositionMap cpu_positions[2], vk_positions[2];
  NormalMap cpu_normals[2], vk_normals[2];
  for (std::size_t i = 0; i < sequence.frames.size(); ++i) {
    const auto& frame = sequence.frames[i];
    const std::size_t cur = i % 2, prev = 1 - cur;
    const Pose previous_pose = i > 0 ? sequence.frames[i - 1].camera_to_world : Pose::Identity();
    const NormalsHistory cpu_history{cpu_normals[prev], cpu_positions[prev], previous_pose};
    const NormalsHistory vk_history{vk_normals[prev], vk_positions[prev], previous_pose};
    normals_raw_depth(frame.noisy, sequence.intrinsics, frame.camera_to_world, i > 0 ? &cpu_history : nullptr, options,
                      cpu_positions[cur], cpu_normals[cur]);
    gpu.run(frame.noisy, sequence.intrinsics, cross_normal_options(options),
            vk_positions[cur], vk_normals[cur]);
    normals_raw_depth_blend(sequence.intrinsics, frame.camera_to_world, i > 0 ? &vk_history : nullptr, options,
                            vk_positions[cur], vk_normals[cur]);
    const std::string what = "method 1 frame " + std::to_string(i);
    expect_agreement(compare(cpu_positions[cur], cpu_normals[cur], vk_positions[cur], vk_normals[cur]), what.c_str());
  }
}

// All per-pixel passes of method 1 on the GPU (cross products, temporal blend, hole filling),
// each frame's history from the GPU's own previous outputs, against the CPU method 1 over three
// orbit frames (moving camera: the reprojection and rotation of the history are exercised).
TEST_F(CrossNormalsVkTest, Method1AllPassesOnGpuEqualsCpuOverThreeOrbitFrames) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  const auto sequence = test::render_sequence(synth::Trajectory::Orbit, 3, 320, 240, {}, 3);
  const NormalsRawDepthOptions options;
  NormalsRawDepthVk gpu(context);
  PositionMap cpu_positions[2], vk_positions[2];
  NormalMap cpu_normals[2], vk_normals[2];
  for (std::size_t i = 0; i < sequence.frames.size(); ++i) {
    const auto& frame = sequence.frames[i];
    const std::size_t cur = i % 2, prev = 1 - cur;
    const Pose previous_pose = i > 0 ? sequence.frames[i - 1].camera_to_world : Pose::Identity();
    const NormalsHistory cpu_history{cpu_normals[prev], cpu_positions[prev], previous_pose};
    const NormalsHistory vk_history{vk_normals[prev], vk_positions[prev], previous_pose};
    normals_raw_depth(frame.noisy, sequence.intrinsics, frame.camera_to_world, i > 0 ? &cpu_history : nullptr, options,
                      cpu_positions[cur], cpu_normals[cur]);
    gpu.run(frame.noisy, sequence.intrinsics, frame.camera_to_world, i > 0 ? &vk_history : nullptr, options,
            vk_positions[cur], vk_normals[cur]);
    const std::string what = "method 1 all on GPU, frame " + std::to_string(i);
    expect_agreement(compare(cpu_positions[cur], cpu_normals[cur], vk_positions[cur], vk_normals[cur]), what.c_str());
    if (const auto ms = gpu.last_gpu_ms()) {
      EXPECT_GT(*ms, 0.0);  // timestamps: the dispatches of this frame
    }
  }
}

// ---- Frame graph -------------------------------------------------------------------------

// Copies the outputs of method 1 every frame (a CPU reader after the stage).
class NormalsReader final : public Stage {
 public:
  std::string name() const override { return "reader"; }
  bool has_side_effects() const override { return true; }
  void declare(StageBuilder& b) override {
    normals_ = b.read<NormalMap>("normals");
    positions_ = b.read<PositionMap>("positions");
  }
  void run(StageContext& ctx) override {
    normals.push_back(ctx.get(normals_));
    positions.push_back(ctx.get(positions_));
  }
  std::vector<NormalMap> normals;
  std::vector<PositionMap> positions;

 private:
  Read<NormalMap> normals_;
  Read<PositionMap> positions_;
};

struct GraphOutputs {
  std::vector<NormalMap> normals;
  std::vector<PositionMap> positions;
  std::vector<double> device_ms;
};

GraphOutputs run_graph(const test::SyntheticSequence& sequence, vk::VulkanContext* context) {
  FrameGraph graph(context ? &context->transfer() : nullptr);
  graph.emplace<test::SequenceSource>(sequence);
  if (context) {
    graph.emplace<NormalsRawDepthVkStage>(*context);
  } else {
    graph.emplace<NormalsRawDepthCpuStage>();
  }
  auto& reader = graph.emplace<NormalsReader>();
  while (graph.run_frame()) {
  }
  GraphOutputs out{std::move(reader.normals), std::move(reader.positions), {}};
  for (const auto& timing : graph.timings()) {
    if (timing.stage == "normals_raw_depth") out.device_ms = timing.device_ms;
  }
  return out;
}

TEST_F(CrossNormalsVkTest, VulkanStageInGraphEqualsCpuStageOverThreeOrbitFrames) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  const auto sequence = test::render_sequence(synth::Trajectory::Orbit, 3, 320, 240, {}, 3);
  const GraphOutputs cpu = run_graph(sequence, nullptr);
  const GraphOutputs gpu = run_graph(sequence, &context);
  ASSERT_EQ(cpu.normals.size(), 3u);
  ASSERT_EQ(gpu.normals.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    ASSERT_TRUE(gpu.normals[i].same_shape(cpu.normals[i]));
    const std::string what = "graph frame " + std::to_string(i);
    expect_agreement(compare(cpu.positions[i], cpu.normals[i], gpu.positions[i], gpu.normals[i]), what.c_str());
  }
  EXPECT_EQ(gpu.device_ms.size(), 3u);  // GPU time of the dispatches reported every frame
}

TEST(NormalsRawDepthBlend, RejectsMismatchedShapes) {
  PositionMap positions(4, 4);
  NormalMap normals(3, 4);
  EXPECT_THROW(normals_raw_depth_blend({}, Pose::Identity(), nullptr, {}, positions, normals), LogicError);
}

}  // namespace
}  // namespace relight::reconstruct
