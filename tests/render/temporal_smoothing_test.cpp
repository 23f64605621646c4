// Temporal smoothing of the indirect light (eqs. 5.11-5.15): blends where the surface is the
// same, takes the new value at disocclusions and where r(p) changes (no ghosting of a moved
// virtual object), and lowers the frame-to-frame flicker of the DIR stage on noisy depth.
#include "relight/render/dir/temporal_smoothing.h"

#include <gtest/gtest.h>

#include "support/vulkan_test_env.h"
#include "relight/reconstruct/depth_warp_merge.h"
#include "relight/reconstruct/normals_from_positions.h"
#include "relight/reconstruct/normals_raw_depth.h"
#include "relight/render/dir/dir_stage.h"
#include "relight/render/scene/procedural_models.h"
#include "relight/truth/scene_from_synth.h"
#include "relight/synth/raycast.h"
#include "relight/synth/trajectory.h"
#include "relight/vk/context.h"
#include "relight/vk/transfer.h"
#include "synthetic_frame_stage.h"

namespace relight::render {
namespace {

constexpr int kSize = 8;

/// A wall at depth `depth` facing a camera at the origin (identity pose), every pixel real.
GBuffer wall(float depth, const MrCamera& camera) {
  const int size = camera.intrinsics.width;
  GBuffer g{PositionMap(size, size), NormalMap(size, size), LabelImage(size, size), Mask(size, size),
            DepthMap(size, size)};
  for (int row = 0; row < size; ++row)
    for (int col = 0; col < size; ++col) {
      const Eigen::Vector3d ray = camera.intrinsics.ray(col, row);
      const Eigen::Vector3d p = ray * (depth / ray.z());
      g.position(row, col) = {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())};
      g.normal(row, col) = {0.f, 0.f, -1.f};
      g.material(row, col) = 1;
      g.distance(row, col) = static_cast<float>(p.norm());
    }
  return g;
}

DifferentialImages indirect(float value, int size = kSize) {
  DifferentialImages images{RadianceImage(size, size), RadianceImage(size, size), CoverageImage(size, size), 1,
                            RadianceImage(size, size), RadianceImage(size, size)};
  for (auto* image : {&images.real_virtual, &images.real, &images.indirect_real_virtual, &images.indirect_real})
    for (Float3& p : image->pixels()) p = {value, value, value};
  return images;
}

MrCamera small_camera(int size = kSize) {
  const double f = size;
  return {PinholeIntrinsics{f, f, (size - 1) / 2.0, (size - 1) / 2.0, size, size}, Pose::Identity()};
}

TEST(TemporalSmoothing, BlendsTheSameSurfaceWithConfidenceCb) {
  const MrCamera camera = small_camera();
  const GBuffer g = wall(2.f, camera);
  DifferentialImages first = indirect(0.5f);
  const TemporalHistory history = smooth_indirect(first, g, camera, nullptr);
  EXPECT_EQ(first.real(3, 3), (Float3{0.5f, 0.5f, 0.5f})) << "the first frame is left alone";
  DifferentialImages second = indirect(0.6f);
  (void)smooth_indirect(second, g, camera, &history);
  // Same surface: eps_pos = eps_n = 0, eps_ill = 0.1^3 * 0.025: c ~ 0.9.
  EXPECT_NEAR(second.indirect_real(3, 3).x, 0.9f * 0.5f + 0.1f * 0.6f, 1e-4f);
  EXPECT_NEAR(second.real(3, 3).x, second.indirect_real(3, 3).x, 1e-6f) << "the total follows its indirect part";
}

// The rows run in parallel; every pixel reads the previous frame and writes only itself, so
// one thread and several give the same images, bit for bit.
TEST(TemporalSmoothing, ParallelRowsGiveTheSerialResult) {
  constexpr int kLarge = 96;
  const MrCamera before = small_camera(kLarge);
  MrCamera after = before;
  after.camera_to_world.translation() = Eigen::Vector3d(0.002, -0.001, 0.0);  // the camera moved a little
  DifferentialImages first = indirect(0.5f, kLarge);
  const TemporalHistory history = smooth_indirect(first, wall(2.f, before), before, nullptr);
  const auto value = [](std::size_t i) { return 0.4f + 0.3f * static_cast<float>((i * 7919) % 101) / 101.f; };
  const auto smoothed = [&](int threads) {
    DifferentialImages next = indirect(0.f, kLarge);
    for (std::size_t i = 0; i < next.indirect_real.size(); ++i) {
      const float v = value(i);  // varies per pixel
      next.indirect_real.pixels()[i] = {v, v, v};
      next.indirect_real_virtual.pixels()[i] = {v, 0.5f * v, v};
    }
    TemporalOptions options;
    options.threads = threads;
    (void)smooth_indirect(next, wall(2.f, after), after, &history, options);
    return next;
  };
  const DifferentialImages serial = smoothed(1), parallel = smoothed(2);
  int blended = 0;
  for (std::size_t i = 0; i < serial.indirect_real.size(); ++i) {
    EXPECT_EQ(serial.indirect_real.pixels()[i], parallel.indirect_real.pixels()[i]) << i;
    EXPECT_EQ(serial.real_virtual.pixels()[i], parallel.real_virtual.pixels()[i]) << i;
    if (serial.indirect_real.pixels()[i].x != value(i)) ++blended;
  }
  EXPECT_GT(blended, kLarge * kLarge / 2) << "most pixels found their previous value";
}

TEST(TemporalSmoothing, TakesTheNewValueAtDisocclusionsAndWhereRealAndVirtualSwap) {
  const MrCamera camera = small_camera();
  DifferentialImages first = indirect(0.5f);
  const TemporalHistory history = smooth_indirect(first, wall(2.f, camera), camera, nullptr);
  DifferentialImages moved = indirect(0.8f);
  (void)smooth_indirect(moved, wall(2.3f, camera), camera, &history);  // 30 cm further: another surface
  EXPECT_FLOAT_EQ(moved.indirect_real(3, 3).x, 0.8f);
  GBuffer now_virtual = wall(2.f, camera);
  now_virtual.virtual_surface(3, 3) = 1;  // a virtual object moved in front of this pixel
  DifferentialImages covered = indirect(0.8f);
  (void)smooth_indirect(covered, now_virtual, camera, &history);
  EXPECT_FLOAT_EQ(covered.indirect_real_virtual(3, 3).x, 0.8f);
  EXPECT_LT(covered.indirect_real_virtual(3, 4).x, 0.6f) << "its neighbour still blends";
}

class TemporalSmoothingStageTest : public relight::test::VulkanTest {};

/// Where the DIR stage's positions and normals come from.
enum class Geometry {
  NoisyPositionsExactNormals,  ///< raw noisy depth back-projected, exact normals
  Method1,                     ///< raw depth, filtered normals (NormalsRawDepthCpuStage, §4.3.2)
  Method2,                     ///< warped and merged depth, filtered normals from it (§4.3.3)
};

const char* to_string(Geometry g) {
  switch (g) {
    case Geometry::NoisyPositionsExactNormals: return "noisy positions, exact normals";
    case Geometry::Method1: return "method 1";
    case Geometry::Method2: return "method 2";
  }
  return "?";
}

/// Mean frame-to-frame change of the indirect light of the DIR stage at the same surface point
/// (real pixels, frames 4-8): each pixel's world point (the G-buffer's) is projected into the
/// previous frame and compared where that frame's pixel holds the same point (within 1 cm).
/// A static camera with fresh Kinect-like depth noise every frame shows every point at its own
/// pixel; on the orbit the points move across the image.
double flicker(vk::VulkanContext& context, bool smoothing, Geometry geometry, const std::vector<Pose>& poses) {
  const PinholeIntrinsics intrinsics{131.25, 131.25, 79.5, 59.5, 160, 120};
  FrameGraph graph(&context.transfer());
  using Output = test::SyntheticFrameStage::Output;
  switch (geometry) {
    case Geometry::NoisyPositionsExactNormals:
      graph.emplace<test::SyntheticFrameStage>(intrinsics, poses, 0.0015f);
      break;
    case Geometry::Method1:
      graph.emplace<test::SyntheticFrameStage>(intrinsics, poses, 0.0015f, Output::Depth);
      graph.emplace<reconstruct::NormalsRawDepthCpuStage>();
      break;
    case Geometry::Method2:
      graph.emplace<test::SyntheticFrameStage>(intrinsics, poses, 0.0015f, Output::Depth);
      graph.emplace<reconstruct::DepthWarpMergeCpuStage>();
      graph.emplace<reconstruct::NormalsRawDepthCpuStage>(reconstruct::NormalsRawDepthOptions{},
                                                          reconstruct::NormalsDepthInput::Filtered);
      break;
  }
  DirSceneContent content;
  content.lights = truth::scene_from_synth(synth::default_indoor_scene()).lights;
  content.objects.emplace_back(make_glossy_pebble(), Placement::parse("0.35,-0.2,0.75,30"));
  DirStageOptions options;
  options.renderer.shadow_tile = 256;
  options.renderer.ism.tile = 32;
  options.temporal_smoothing = smoothing;
  add_dir_stages(graph, Backend::Vulkan, &context, std::move(content), options);
  graph.keep("L_rv_indirect");
  graph.keep("dir_gbuffer");
  graph.compile();
  RadianceImage previous;
  GBuffer previous_gbuffer;
  Pose previous_pose;
  double change = 0.0;
  int samples = 0;
  for (int frame = 0; frame < 9; ++frame) {
    EXPECT_TRUE(graph.run_frame());
    const RadianceImage& now = *graph.find<RadianceImage>("L_rv_indirect");
    const CoverageImage& coverage = *graph.find<CoverageImage>("virtual_coverage");
    const GBuffer& gbuffer = *graph.find<GBuffer>("dir_gbuffer");
    const Pose pose = graph.find<FrameInfo>("frame")->camera_to_world.value_or(Pose::Identity());
    if (frame >= 4) {  // past the first blends
      const Pose previous_from_world = previous_pose.inverse();
      for (std::size_t i = 0; i < now.size(); ++i) {
        if (coverage.pixels()[i] != 0.f || gbuffer.distance.pixels()[i] == 0.f) continue;
        const Float3& p = gbuffer.position.pixels()[i];
        const Eigen::Vector3d world(p.x, p.y, p.z);
        const Eigen::Vector3d in_previous = previous_from_world * world;
        if (in_previous.z() <= 0.0) continue;
        const Eigen::Vector2d uv = intrinsics.project(in_previous);
        const int u = static_cast<int>(std::floor(uv.x() + 0.5)), v = static_cast<int>(std::floor(uv.y() + 0.5));
        if (u < 0 || v < 0 || u >= intrinsics.width || v >= intrinsics.height) continue;
        const std::size_t j = static_cast<std::size_t>(v) * static_cast<std::size_t>(intrinsics.width) + static_cast<std::size_t>(u);
        if (previous_gbuffer.distance.pixels()[j] == 0.f || previous_gbuffer.virtual_surface.pixels()[j]) continue;
        const Float3& q = previous_gbuffer.position.pixels()[j];
        if ((Eigen::Vector3d(q.x, q.y, q.z) - world).norm() > 0.03) continue;
        change += length(now.pixels()[i] - previous.pixels()[j]);
        ++samples;
      }
    }
    previous = now;
    previous_gbuffer = gbuffer;
    previous_pose = pose;
  }
  return change / std::max(samples, 1);
}

// The goal, at least 50 % less flicker, on a static camera and on the orbit, for every
// kind of geometry. Measured (static / orbit): noisy positions with exact normals 71 / 62 %,
// method 1 73 / 67 %, method 2 88 / 82 %. (Comparing pixels rather than surface points, the
// static camera gave 44 / 40 / 75 %: a pixel on a depth edge swaps surfaces with the noise, and
// no temporal filter may blend those.)
TEST_F(TemporalSmoothingStageTest, CutsTheFlickerOfIndirectLightOnNoisyDepth) {
  RELIGHT_REQUIRE_VULKAN_CONTEXT(context);
  const std::vector<Pose> still{synth::look_at({1.2, -1.1, 1.35}, {0.25, -0.1, 0.75})};
  const std::vector<Pose> orbit = synth::make_trajectory(synth::Trajectory::Orbit, 9, 0, synth::default_indoor_scene());
  for (const bool moving : {false, true}) {
    for (const Geometry geometry : {Geometry::NoisyPositionsExactNormals, Geometry::Method1, Geometry::Method2}) {
      const double without = flicker(context, false, geometry, moving ? orbit : still);
      const double with = flicker(context, true, geometry, moving ? orbit : still);
      std::printf("flicker, %s, %s: %.5f without smoothing, %.5f with (%.0f %% less)\n", moving ? "orbit" : "static",
                  to_string(geometry), without, with, 100.0 * (1.0 - with / without));
      EXPECT_GT(without, 0.0) << "the noise moves the VPLs";
      EXPECT_LT(with, 0.5 * without) << (moving ? "orbit, " : "static, ") << to_string(geometry);
    }
  }
}

}  // namespace
}  // namespace relight::render
