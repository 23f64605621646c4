// Method 2's warp and merge on Vulkan (depth_warp_merge_vk.h) against the CPU reference
// (depth_warp_merge.h): per frame on the same inputs along a moving camera, and as a drop-in
// frame-graph stage keeping its own history.
#include "relight/reconstruct/depth_warp_merge_vk.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "relight/core/frame_graph.h"
#include "relight/vk/context.h"
#include "relight/vk/transfer.h"
#include "synthetic_sequence.h"
#include "support/vulkan_test_env.h"

namespace relight::reconstruct {
namespace {

using DepthWarpMergeVkTest = test::VulkanTest;

struct Agreement {
  int compared = 0, depth_close = 0, weight_equal = 0;
};

// Pixels where either map has depth: depth within 1 mm (the tolerance), weight equal.
Agreement agreement(const DepthMap& cpu, const DepthWeightMap& cpu_weight, const DepthMap& gpu,
                    const DepthWeightMap& gpu_weight) {
  Agreement a;
  for (std::size_t i = 0; i < cpu.size(); ++i) {
    if (!(cpu.pixels()[i] > 0.f) && !(gpu.pixels()[i] > 0.f)) continue;
    ++a.compared;
    a.depth_close += std::fabs(cpu.pixels()[i] - gpu.pixels()[i]) <= 1e-3f ? 1 : 0;
    a.weight_equal += cpu_weight.pixels()[i] == gpu_weight.pixels()[i] ? 1 : 0;
  }
  return a;
}

TEST_F(DepthWarpMergeVkTest, EachFrameOfAnOrbitAgreesWithTheCpu) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  const auto sequence = test::render_sequence(synth::Trajectory::Orbit, 5, 320, 240, {}, 3);  // 2 degrees a frame
  DepthWarpMergeVk gpu(context);
  DepthMap filtered, warped;
  DepthWeightMap weight, warped_weight;
  for (std::size_t i = 0; i < sequence.frames.size(); ++i) {
    const auto& frame = sequence.frames[i];
    const Pose current_from_prev =
        i > 0 ? Pose(frame.camera_to_world.inverse() * sequence.frames[i - 1].camera_to_world) : Pose::Identity();
    DepthMap cpu_depth, gpu_depth;
    DepthWeightMap cpu_weight, gpu_weight;
    if (i > 0) warp_depth(filtered, weight, sequence.intrinsics, current_from_prev, {}, warped, warped_weight);
    merge_depth(frame.noisy, i > 0 ? warped : DepthMap{}, i > 0 ? warped_weight : DepthWeightMap{}, {}, cpu_depth,
                cpu_weight);
    gpu.run(frame.noisy, i > 0 ? &filtered : nullptr, i > 0 ? &weight : nullptr, sequence.intrinsics, current_from_prev,
            {}, gpu_depth, gpu_weight);
    const Agreement a = agreement(cpu_depth, cpu_weight, gpu_depth, gpu_weight);
    std::printf("frame %zu: %d pixels, depth within 1 mm %.4f, same weight %.4f\n", i, a.compared,
                static_cast<double>(a.depth_close) / a.compared, static_cast<double>(a.weight_equal) / a.compared);
    EXPECT_GT(a.compared, 320 * 240 / 2);
    EXPECT_GE(a.depth_close, a.compared * 99 / 100) << "frame " << i;
    EXPECT_GE(a.weight_equal, a.compared * 99 / 100) << "frame " << i;
    filtered = std::move(cpu_depth);  // both continue from the reference's history
    weight = std::move(cpu_weight);
  }
  EXPECT_GT(std::count_if(weight.pixels().begin(), weight.pixels().end(), [](float w) { return w >= 5.f; }),
            320 * 240 / 2)
      << "the history was carried over all five frames";
}

TEST_F(DepthWarpMergeVkTest, StageIsADropInForTheCpuStage) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  const auto sequence = test::render_sequence(synth::Trajectory::Orbit, 4, 160, 120, {}, 3);
  const auto run = [&](bool on_gpu) {
    FrameGraph graph(&context.transfer());
    graph.emplace<test::SequenceSource>(sequence);
    if (on_gpu) graph.emplace<DepthWarpMergeVkStage>(context);
    else graph.emplace<DepthWarpMergeCpuStage>();
    graph.keep("depth_filtered");
    graph.compile();
    DepthMap last;
    while (graph.run_frame()) last = *graph.find<DepthMap>("depth_filtered");
    return last;
  };
  const DepthMap cpu = run(false), gpu = run(true);
  int compared = 0, close = 0;
  for (std::size_t i = 0; i < cpu.size(); ++i) {
    if (!(cpu.pixels()[i] > 0.f)) continue;
    ++compared;
    close += std::fabs(cpu.pixels()[i] - gpu.pixels()[i]) <= 1e-3f ? 1 : 0;
  }
  EXPECT_GT(compared, 160 * 120 / 2);
  EXPECT_GE(close, compared * 98 / 100);  // four frames of each backend's own history
}

// The history (filtered depth and weight) stays on the device, and after the first two frames
// (one without history, one that fills the second half of the graph's double buffer) no frame
// allocates device memory: the stage's scratch and the graph's buffers are reused.
TEST_F(DepthWarpMergeVkTest, ASteadyRunAllocatesNoDeviceMemory) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  const auto sequence = test::render_sequence(synth::Trajectory::Orbit, 10, 80, 60, {}, 5);
  FrameGraph graph(&context.transfer());
  graph.emplace<test::SequenceSource>(sequence);
  graph.emplace<DepthWarpMergeVkStage>(context);
  graph.keep("depth_filtered");
  graph.compile();
  const std::uint64_t before = context.memory_allocations();
  std::vector<std::uint64_t> allocations;
  while (graph.run_frame()) allocations.push_back(context.memory_allocations());
  ASSERT_EQ(allocations.size(), 10u);
  EXPECT_GT(allocations.front(), before);  // the first frame did allocate (the count works)
  EXPECT_EQ(allocations.back(), allocations[1]) << "device memory allocated in frames 3-10";
}

}  // namespace
}  // namespace relight::reconstruct
