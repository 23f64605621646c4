// Method 1 (normals_raw_depth.h) and its building blocks, against the synthetic scene's exact
// normals. The numbers quoted in comments were measured at 320x240 with Kinect v1 noise.
#include "relight/reconstruct/normals_raw_depth.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "relight/core/frame_graph.h"
#include "relight/reconstruct/normal_error.h"
#include "relight/reconstruct/normals_from_positions.h"
#include "synthetic_sequence.h"

namespace relight {
namespace {

// Exact plane z = z0 + a x (tilted about the camera's y axis) seen by a pinhole camera.
DepthMap tilted_plane(const PinholeIntrinsics& k, double z0, double slope) {
  DepthMap depth(k.width, k.height);
  for (int r = 0; r < k.height; ++r) {
    for (int c = 0; c < k.width; ++c) {
      // z = z0 + slope * x with x = (c - cx) z / fx  =>  z = z0 / (1 - slope (c - cx) / fx)
      depth(r, c) = static_cast<float>(z0 / (1.0 - slope * (c - k.cx) / k.fx));
    }
  }
  return depth;
}

PinholeIntrinsics small_camera() { return {.fx = 100, .fy = 100, .cx = 39.5, .cy = 29.5, .width = 80, .height = 60}; }

TEST(NormalsFromPositions, TiltedPlaneGivesItsExactNormalTowardsTheCamera) {
  const PinholeIntrinsics k = small_camera();
  const DepthMap depth = tilted_plane(k, 2.0, 0.5);
  PositionMap positions;
  positions_from_depth(depth, k, positions);
  EXPECT_NEAR(positions(10, 20).x, (20 - k.cx) / k.fx * depth(10, 20), 1e-6);
  for (int stride : {1, 4}) {
    NormalMap normals;
    normals_from_positions(positions, normals, {.stride = stride});
    // Plane z - 0.5 x = 2: normal ∝ (-0.5, 0, 1), flipped towards the camera: (0.5, 0, -1)/|.|.
    const Float3 expected{static_cast<float>(0.5 / std::sqrt(1.25)), 0.f, static_cast<float>(-1 / std::sqrt(1.25))};
    for (int r = 0; r < k.height; ++r) {
      for (int c = 0; c < k.width; ++c) {
        ASSERT_GT(dot(normals(r, c), expected), 0.99999f) << "stride " << stride << " at " << r << "," << c;
      }
    }
  }
}

TEST(NormalsFromPositions, DiscontinuitiesAndHolesUseTheOtherSideOrNothing) {
  const PinholeIntrinsics k = small_camera();
  DepthMap depth(k.width, k.height, 2.f);
  for (int r = 0; r < k.height; ++r) {
    for (int c = 40; c < k.width; ++c) depth(r, c) = 1.f;  // a step of 1 m at column 40
  }
  depth(30, 10) = 0.f;
  PositionMap positions;
  positions_from_depth(depth, k, positions);
  NormalMap normals;
  normals_from_positions(positions, normals, {.stride = 1});
  // Column 39's forward neighbour is across the step: the backward difference keeps the plane normal.
  EXPECT_NEAR(normals(20, 39).z, -1.f, 1e-5f);
  EXPECT_NEAR(normals(20, 40).z, -1.f, 1e-5f);
  EXPECT_FALSE(is_valid_normal(normals(30, 10)));  // no depth, no normal
  EXPECT_NEAR(normals(30, 9).z, -1.f, 1e-5f);      // neighbour of a hole: backward difference
}

// Mean angular error over the valid pixels of the last frame of a static-camera sequence.
struct Method1Errors {
  AngularError raw, stride4, filtered;
};

Method1Errors run_method1(const test::SyntheticSequence& sequence, const NormalsRawDepthOptions& options = {}) {
  PositionMap positions[2];
  NormalMap normals[2];
  for (std::size_t i = 0; i < sequence.frames.size(); ++i) {
    const auto& frame = sequence.frames[i];
    const std::size_t cur = i % 2, prev = 1 - cur;
    const NormalsHistory history{normals[prev], positions[prev], i > 0 ? sequence.frames[i - 1].camera_to_world : Pose::Identity()};
    normals_raw_depth(frame.noisy, sequence.intrinsics, frame.camera_to_world, i > 0 ? &history : nullptr, options,
                      positions[cur], normals[cur]);
  }
  const auto& last = sequence.frames.back();
  const NormalMap& filtered = normals[(sequence.frames.size() - 1) % 2];
  Method1Errors errors;
  PositionMap raw_positions;
  positions_from_depth(last.noisy, sequence.intrinsics, raw_positions);
  NormalMap raw;
  normals_from_positions(raw_positions, raw, {.stride = 1});
  errors.raw = angular_error(raw, last.true_normals);
  NormalMap single;
  normals_raw_depth(last.noisy, sequence.intrinsics, last.camera_to_world, nullptr, options, raw_positions, single);
  errors.stride4 = angular_error(single, last.true_normals);
  errors.filtered = angular_error(filtered, last.true_normals);
  return errors;
}

TEST(NormalsRawDepth, StaticCameraTenFramesIsFarBetterThanRawNormals) {
  const auto sequence = test::render_sequence(synth::Trajectory::Static, 10);
  const Method1Errors e = run_method1(sequence);
  std::printf("static: raw %.2f deg, method 1 one frame %.2f deg, method 1 ten frames %.2f deg (coverage %.3f)\n",
              e.raw.mean_deg, e.stride4.mean_deg, e.filtered.mean_deg, e.filtered.coverage);
  EXPECT_LT(e.filtered.mean_deg, 0.5 * e.raw.mean_deg);
  EXPECT_LT(e.filtered.mean_deg, e.stride4.mean_deg);  // the temporal filter helps beyond the stride
  EXPECT_GE(e.filtered.coverage, e.raw.coverage);      // hole filling: no pixel lost to the stride
}

TEST(NormalsRawDepth, OrbitWithPosesStaysBetterThanRaw) {
  const auto sequence = test::render_sequence(synth::Trajectory::Orbit, 8);
  const Method1Errors e = run_method1(sequence);
  std::printf("orbit: raw %.2f deg, method 1 one frame %.2f deg, method 1 eight frames %.2f deg\n", e.raw.mean_deg,
              e.stride4.mean_deg, e.filtered.mean_deg);
  EXPECT_LT(e.filtered.mean_deg, 0.5 * e.raw.mean_deg);
  EXPECT_LT(e.filtered.mean_deg, e.stride4.mean_deg);
}

TEST(NormalsRawDepth, IgnoringThePoseOnAnOrbitIsWorseThanUsingIt) {
  // The pose change must be applied: feeding identity poses blends normals of the wrong pixels
  // and the wrong camera frame.
  // Every 6th orbit frame: 4 degrees of rotation per frame.
  auto sequence = test::render_sequence(synth::Trajectory::Orbit, 8, 320, 240, {}, 6);
  const double with_pose = run_method1(sequence).filtered.mean_deg;
  const Pose first = sequence.frames.front().camera_to_world;
  for (auto& frame : sequence.frames) frame.camera_to_world = first;
  const double without_pose = run_method1(sequence).filtered.mean_deg;
  std::printf("orbit: with poses %.2f deg, poses ignored %.2f deg\n", with_pose, without_pose);
  EXPECT_LT(with_pose, without_pose);
}

TEST(NormalsRawDepth, FirstFrameIsStrideFourNormalsWithHolesFilled) {
  const PinholeIntrinsics k = small_camera();
  DepthMap depth = tilted_plane(k, 1.5, -0.3);
  depth(20, 20) = 0.f;
  PositionMap positions;
  NormalMap normals;
  normals_raw_depth(depth, k, Pose::Identity(), nullptr, {}, positions, normals);
  const Float3 expected{static_cast<float>(-0.3 / std::sqrt(1.09)), 0.f, static_cast<float>(-1 / std::sqrt(1.09))};
  for (int r = 0; r < k.height; ++r) {
    for (int c = 0; c < k.width; ++c) {
      if (r == 20 && c == 20) {
        EXPECT_FALSE(is_valid_normal(normals(r, c)));
        continue;
      }
      ASSERT_GT(dot(normals(r, c), expected), 0.99999f) << r << "," << c;
    }
  }
}

TEST(NormalsRawDepth, DisocclusionResetsTheHistory) {
  // Previous frame: a plane at 2 m with normals deliberately wrong; current: a plane at 1 m.
  // The depth change (1 m > 0.1 m) must discard the history, so the result is the fresh normal.
  const PinholeIntrinsics k = small_camera();
  const DepthMap near = tilted_plane(k, 1.0, 0.0);
  PositionMap previous_positions;
  positions_from_depth(tilted_plane(k, 2.0, 0.0), k, previous_positions);
  const float s = static_cast<float>(std::sqrt(0.5));
  const NormalMap previous_normals(k.width, k.height, Float3{s, 0.f, -s});
  const NormalsHistory history{previous_normals, previous_positions, Pose::Identity()};
  PositionMap positions;
  NormalMap normals;
  normals_raw_depth(near, k, Pose::Identity(), &history, {}, positions, normals);
  EXPECT_NEAR(normals(30, 40).z, -1.f, 1e-5f);
  // Same depth in both frames: now the history counts (c >= c_B = 0.9), the normal tilts towards it.
  const NormalsHistory same_depth{previous_normals, positions, Pose::Identity()};
  NormalMap blended;
  PositionMap unused;
  normals_raw_depth(near, k, Pose::Identity(), &same_depth, {}, unused, blended);
  EXPECT_GT(blended(30, 40).x, 0.5f);
}

// ---- Frame graph -------------------------------------------------------------------------

TEST(NormalsRawDepthStage, GraphRunEqualsDirectCallsWithHistory) {
  const auto sequence = test::render_sequence(synth::Trajectory::Orbit, 3, 160, 120);
  FrameGraph graph;
  graph.emplace<test::SequenceSource>(sequence);
  graph.emplace<NormalsRawDepthCpuStage>();
  graph.keep("normals");
  graph.compile();
  PositionMap positions[2];
  NormalMap normals[2];
  for (std::size_t i = 0; i < 3; ++i) {
    ASSERT_TRUE(graph.run_frame());
    const std::size_t cur = i % 2, prev = 1 - cur;
    const NormalsHistory history{normals[prev], positions[prev], i > 0 ? sequence.frames[i - 1].camera_to_world : Pose::Identity()};
    normals_raw_depth(sequence.frames[i].noisy, sequence.intrinsics, sequence.frames[i].camera_to_world,
                      i > 0 ? &history : nullptr, {}, positions[cur], normals[cur]);
    const NormalMap* from_graph = graph.find<NormalMap>("normals");
    ASSERT_NE(from_graph, nullptr);
    EXPECT_TRUE(*from_graph == normals[cur]) << "frame " << i;
  }
}

}  // namespace
}  // namespace relight
