// Camera tracking on synthetic RGB-D with ground truth: the odometry's accuracy on the orbit
// and hand-held paths with Kinect v1 noise, failure as a state (a blank wall, a jump), the
// support plane that levels the world, the trajectory metrics, and the tracking stage's sources.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "relight/capture/camera_tracking_stage.h"
#include "relight/capture/rgbd_odometry.h"
#include "relight/capture/support_plane.h"
#include "relight/capture/trajectory_error.h"
#include "relight/core/error.h"
#include "relight/synth/kinect_noise.h"
#include "relight/synth/raycast.h"
#include "relight/synth/scene.h"
#include "relight/synth/sequence.h"
#include "relight/synth/trajectory.h"

namespace relight::capture {
namespace {

struct Frame {
  Pose truth;
  DepthMap depth;
  ColorImage color;
};

ColorImage to_color(const RadianceImage& radiance) {
  ColorImage out(radiance.width(), radiance.height());
  for (int r = 0; r < radiance.height(); ++r) {
    for (int c = 0; c < radiance.width(); ++c) {
      const auto& p = radiance(r, c);
      const auto channel = [](float v) {
        return static_cast<std::uint8_t>(std::lround(255.f * std::pow(std::clamp(v, 0.f, 1.f), 1.f / 2.2f)));
      };
      out(r, c) = Rgb8{channel(p.x), channel(p.y), channel(p.z)};
    }
  }
  return out;
}

/// 320x240 frames of a synth trajectory with Kinect v1 noise; every `step`-th pose (the orbit at
/// step 3 turns 2 degrees a frame, the fast hand-held rotation of the TUM rpy sequences).
std::vector<Frame> render(synth::Trajectory trajectory, int frames, int step, PinholeIntrinsics& intrinsics) {
  synth::SynthOptions options;
  options.width = 320;
  options.height = 240;
  intrinsics = synth::synth_intrinsics(options);
  const synth::Scene scene = synth::default_indoor_scene();
  const auto poses = synth::make_trajectory(trajectory, frames * step, 3, scene);
  std::vector<Frame> out;
  for (int i = 0; i < frames; ++i) {
    const Pose pose = poses[static_cast<std::size_t>(i * step)];
    synth::RenderedFrame truth = synth::render_frame(scene, intrinsics, pose);
    DepthMap noisy = synth::apply_kinect_noise(truth.depth, truth.normals, intrinsics, options.kinect, 7,
                                               static_cast<std::uint64_t>(i));
    out.push_back({pose, std::move(noisy), to_color(truth.radiance)});
  }
  return out;
}

RgbdOdometryOptions options_for_320x240() {
  RgbdOdometryOptions options;
  options.levels = 3;
  options.finest_level = 0;  // 320x240 is already the half size the defaults stop at
  return options;
}

struct TrackedRun {
  std::vector<Pose> estimate, truth;
  std::vector<OdometryResult> results;
};

TrackedRun track(const std::vector<Frame>& frames, const PinholeIntrinsics& intrinsics, RgbdOdometryOptions options = options_for_320x240()) {
  RgbdOdometry odometry(options);
  odometry.reset(frames.front().truth);
  TrackedRun run;
  for (const Frame& frame : frames) {
    run.results.push_back(odometry.track(frame.depth, frame.color, intrinsics));
    run.estimate.push_back(run.results.back().camera_to_world);
    run.truth.push_back(frame.truth);
  }
  return run;
}

double degrees(double radians) { return radians * 180.0 / std::numbers::pi; }

// Measured: orbit ATE 0.21 cm, RPE 0.045 deg; hand-held ATE 0.11 cm, RPE 0.040 deg.
TEST(RgbdOdometry, TracksTheOrbitAndTheHandheldPathWithKinectNoise) {
  for (const auto trajectory : {synth::Trajectory::Orbit, synth::Trajectory::Handheld}) {
    PinholeIntrinsics intrinsics;
    const auto frames = render(trajectory, 24, 3, intrinsics);
    const TrackedRun run = track(frames, intrinsics);
    for (const auto& result : run.results) EXPECT_TRUE(result.quality.tracked) << result.quality.failure;
    const double ate_cm = 100.0 * absolute_trajectory_error(run.estimate, run.truth);
    const RelativePoseError rpe = relative_pose_error(run.estimate, run.truth);
    std::printf("%s: ATE %.3f cm, RPE %.4f deg %.3f mm\n", synth::to_string(trajectory), ate_cm, rpe.rotation_deg,
                1000 * rpe.translation_m);
    EXPECT_LT(ate_cm, 0.5);
    EXPECT_LT(rpe.rotation_deg, 0.1);
    // Started at the true pose, the tracker stays in the true world frame (no alignment needed).
    EXPECT_LT((run.estimate.back().translation() - run.truth.back().translation()).norm(), 0.01);
  }
}

// The keyframe model is a byte budget: with room for three 320x240 keyframes (0.8 MB each) the
// orbit, which makes a keyframe every two frames, keeps at most three and still tracks.
TEST(RgbdOdometry, TheKeyframeModelStaysWithinItsByteBudget) {
  PinholeIntrinsics intrinsics;
  const auto frames = render(synth::Trajectory::Orbit, 24, 3, intrinsics);
  RgbdOdometryOptions options = options_for_320x240();
  RgbdOdometry unbounded(options);
  options.model_budget_mb = 2.6f;
  RgbdOdometry bounded(options);
  unbounded.reset(frames.front().truth);
  bounded.reset(frames.front().truth);
  std::vector<Pose> estimate, truth;
  for (const Frame& frame : frames) {
    (void)unbounded.track(frame.depth, frame.color, intrinsics);
    const auto result = bounded.track(frame.depth, frame.color, intrinsics);
    EXPECT_TRUE(result.quality.tracked) << result.quality.failure;
    EXPECT_LE(bounded.model_bytes(), static_cast<std::size_t>(2.6 * 1024 * 1024));
    estimate.push_back(result.camera_to_world);
    truth.push_back(frame.truth);
  }
  std::printf("keyframes %zu (%.2f MB) unbounded, %zu (%.2f MB) within 2.6 MB\n", unbounded.keyframe_count(),
              static_cast<double>(unbounded.model_bytes()) / (1024 * 1024), bounded.keyframe_count(),
              static_cast<double>(bounded.model_bytes()) / (1024 * 1024));
  EXPECT_GT(unbounded.keyframe_count(), 5u);  // the budget matters in this run
  EXPECT_GE(bounded.keyframe_count(), 2u);
  EXPECT_LE(bounded.keyframe_count(), 3u);
  EXPECT_LT(100.0 * absolute_trajectory_error(estimate, truth), 1.0);
}

TEST(RgbdOdometry, ABlankWallIsLostWithinAFrameHeldAndRecoveredFrom) {
  PinholeIntrinsics intrinsics;
  const auto frames = render(synth::Trajectory::Orbit, 12, 3, intrinsics);
  RgbdOdometry odometry(options_for_320x240());
  odometry.reset(frames.front().truth);
  const DepthMap wall(intrinsics.width, intrinsics.height, 0.8f);
  const ColorImage grey(intrinsics.width, intrinsics.height, Rgb8{128, 128, 128});
  Pose last_good;
  for (int i = 0; i < 12; ++i) {
    const bool blank = i >= 5 && i < 8;  // the camera faces a blank wall for three frames
    const auto result = blank ? odometry.track(wall, grey, intrinsics)
                              : odometry.track(frames[static_cast<std::size_t>(i)].depth,
                                               frames[static_cast<std::size_t>(i)].color, intrinsics);
    if (blank) {
      EXPECT_FALSE(result.quality.tracked) << "frame " << i;
      EXPECT_FALSE(result.quality.failure.empty());
      EXPECT_TRUE(result.camera_to_world.isApprox(last_good)) << "frame " << i << ": the last good pose is held";
    } else {
      EXPECT_TRUE(result.quality.tracked) << "frame " << i << ": " << result.quality.failure;
      EXPECT_LT((result.camera_to_world.translation() - frames[static_cast<std::size_t>(i)].truth.translation()).norm(),
                0.02)
          << "frame " << i;
      last_good = result.camera_to_world;
    }
  }
}

TEST(RgbdOdometry, AJumpIsNeverTrackedWithAWrongPose) {
  PinholeIntrinsics intrinsics;
  const auto frames = render(synth::Trajectory::Orbit, 30, 3, intrinsics);
  RgbdOdometry odometry(options_for_320x240());
  odometry.reset(frames.front().truth);
  // Frames 6..20 are dropped: the camera jumps by 30 degrees around the table.
  int lost = 0;
  for (int i = 0; i < 30; ++i) {
    if (i >= 6 && i < 21) continue;
    const Frame& frame = frames[static_cast<std::size_t>(i)];
    const auto result = odometry.track(frame.depth, frame.color, intrinsics);
    const double error = (result.camera_to_world.translation() - frame.truth.translation()).norm();
    if (result.quality.tracked) {
      EXPECT_LT(error, 0.05) << "frame " << i << " tracked with a pose 5 cm off";
    } else {
      ++lost;
    }
  }
  std::printf("frames reported lost after the jump: %d\n", lost);
}

TEST(SupportPlane, LevelsTheWorldOnTheTable) {
  PinholeIntrinsics intrinsics;
  const auto frames = render(synth::Trajectory::Static, 1, 1, intrinsics);
  const auto plane = dominant_support_plane(frames[0].depth, intrinsics);
  ASSERT_TRUE(plane.has_value());
  // The table top is the scene's largest up-facing plane: world z seen from the camera.
  const Eigen::Vector3d up_in_camera = frames[0].truth.linear().transpose() * Eigen::Vector3d::UnitZ();
  EXPECT_LT(degrees(std::acos(std::clamp(plane->normal.dot(up_in_camera), -1.0, 1.0))), 2.0);
  const Pose world = world_from_support_plane(*plane);
  EXPECT_NEAR(world.linear().determinant(), 1.0, 1e-9);
  // The levelled world's z is the true up, and the camera's height is its height above the plane.
  EXPECT_LT(degrees(std::acos(std::clamp((world.linear() * up_in_camera).dot(Eigen::Vector3d::UnitZ()), -1.0, 1.0))),
            2.0);
  EXPECT_NEAR(world.translation().z(), plane->offset, 1e-9);
  EXPECT_FALSE(dominant_support_plane(DepthMap(320, 240, 0.f), intrinsics).has_value());
}

// `--place-at`'s surface: the local plane around a pixel of the noisy depth is the surface the
// pixel sees - the table top, and the top of the box standing on it, whose edges the window
// straddles - not a mix of the two.
TEST(SupportPlane, LocalPlaneAtAPixelIsTheSurfaceSeenThere) {
  PinholeIntrinsics intrinsics;
  const auto frames = render(synth::Trajectory::Static, 1, 1, intrinsics);
  const Pose world_to_camera = frames[0].truth.inverse();
  const Eigen::Vector3d up_in_camera = world_to_camera.linear() * Eigen::Vector3d::UnitZ();
  // Table top beside the box; the middle of the box's top (0.20 x 0.18 m, 0.12 m above the table).
  for (const Eigen::Vector3d& world : {Eigen::Vector3d(-0.25, -0.15, 0.75), Eigen::Vector3d(0.32, 0.17, 0.87)}) {
    const Eigen::Vector3d camera = world_to_camera * world;
    const Eigen::Vector2d pixel = intrinsics.project(camera);
    ASSERT_TRUE(pixel.x() >= 0 && pixel.y() >= 0 && pixel.x() < 320 && pixel.y() < 240) << pixel.transpose();
    const auto plane = local_plane_at(frames[0].depth, intrinsics, pixel.x(), pixel.y());
    ASSERT_TRUE(plane.has_value()) << world.transpose();
    EXPECT_LT(degrees(std::acos(std::clamp(plane->normal.dot(up_in_camera), -1.0, 1.0))), 3.0) << world.transpose();
    const auto hit = plane->ray_hit(intrinsics, pixel.x(), pixel.y());
    ASSERT_TRUE(hit.has_value());
    EXPECT_LT((frames[0].truth * *hit - world).norm(), 0.01) << world.transpose();
  }
  EXPECT_FALSE(local_plane_at(DepthMap(320, 240, 0.f), intrinsics, 160, 120).has_value());
  EXPECT_FALSE(local_plane_at(frames[0].depth, intrinsics, 320, 10).has_value());
  EXPECT_FALSE(local_plane_at(frames[0].depth, intrinsics, -1, 10).has_value());
}

TEST(TrajectoryError, IsZeroForARigidlyMovedCopyAndMeasuresANoisyOne) {
  std::vector<Pose> truth, moved, shifted;
  Pose offset = Pose::Identity();
  offset.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  offset.translation() << 0.3, -1.0, 2.0;
  for (int i = 0; i < 20; ++i) {
    Pose pose = Pose::Identity();
    pose.linear() = Eigen::AngleAxisd(0.05 * i, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    pose.translation() << std::cos(0.1 * i), std::sin(0.1 * i), 0.01 * i;
    truth.push_back(pose);
    moved.push_back(offset * pose);
    Pose off = pose;
    off.translation().z() += (i % 2 ? 0.01 : -0.01);  // +-1 cm, alternating
    shifted.push_back(off);
  }
  EXPECT_NEAR(absolute_trajectory_error(moved, truth), 0.0, 1e-9);
  EXPECT_NEAR(relative_pose_error(moved, truth).rotation_deg, 0.0, 1e-6);
  EXPECT_NEAR(absolute_trajectory_error(shifted, truth), 0.01, 1e-3);
  EXPECT_NEAR(relative_pose_error(shifted, truth).translation_m, 0.02, 1e-3);
}

// A source that plays frames with or without their true poses into "source_frame".
class FramesSource final : public Stage {
 public:
  FramesSource(const std::vector<Frame>& frames, PinholeIntrinsics intrinsics, bool with_poses)
      : frames_(frames), intrinsics_(intrinsics), with_poses_(with_poses) {}
  std::string name() const override { return "source"; }
  bool has_side_effects() const override { return true; }
  void declare(StageBuilder& b) override {
    depth_ = b.write<DepthMap>("depth");
    color_ = b.write<ColorImage>("color");
    frame_ = b.write<FrameInfo>("source_frame");
  }
  void run(StageContext& ctx) override {
    const auto i = static_cast<std::size_t>(ctx.frame_index());
    if (i >= frames_.size()) return ctx.end_of_stream();
    ctx.get(depth_) = frames_[i].depth;
    ctx.get(color_) = frames_[i].color;
    ctx.get(frame_) = FrameInfo{ctx.frame_index(), 1.0 + ctx.frame_index() / 30.0,
                                with_poses_ ? std::optional<Pose>(frames_[i].truth) : std::nullopt, intrinsics_};
  }

 private:
  const std::vector<Frame>& frames_;
  PinholeIntrinsics intrinsics_;
  bool with_poses_;
  Write<DepthMap> depth_;
  Write<ColorImage> color_;
  Write<FrameInfo> frame_;
};

std::vector<FrameInfo> run_tracking(const std::vector<Frame>& frames, const PinholeIntrinsics& intrinsics,
                                    bool with_poses, const CameraTrackingOptions& options,
                                    std::vector<CameraPose>* poses = nullptr) {
  FrameGraph graph;
  graph.emplace<FramesSource>(frames, intrinsics, with_poses);
  graph.emplace<CameraTrackingStage>(options);
  graph.keep("frame");
  graph.keep("camera_pose");
  std::vector<FrameInfo> out;
  while (graph.run_frame()) {
    out.push_back(*graph.find<FrameInfo>("frame"));
    if (poses) poses->push_back(*graph.find<CameraPose>("camera_pose"));
  }
  return out;
}

TEST(CameraTrackingStage, AutoUsesTheSequencePosesAndElseOdometryInALevelledWorld) {
  PinholeIntrinsics intrinsics;
  const auto frames = render(synth::Trajectory::Orbit, 8, 3, intrinsics);
  CameraTrackingOptions automatic;
  automatic.odometry = options_for_320x240();
  std::vector<CameraPose> poses;
  const auto with = run_tracking(frames, intrinsics, true, automatic, &poses);
  ASSERT_EQ(with.size(), frames.size());
  EXPECT_EQ(poses.front().source, PoseSource::Sequence);
  for (std::size_t i = 0; i < frames.size(); ++i) EXPECT_TRUE(with[i].camera_to_world->isApprox(frames[i].truth));

  poses.clear();
  const auto without = run_tracking(frames, intrinsics, false, automatic, &poses);
  ASSERT_EQ(without.size(), frames.size());
  EXPECT_EQ(poses.front().source, PoseSource::Odometry);
  std::vector<Pose> estimate, truth;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    ASSERT_TRUE(without[i].camera_to_world.has_value());
    EXPECT_FALSE(poses[i].held) << poses[i].failure;
    estimate.push_back(*without[i].camera_to_world);
    truth.push_back(frames[i].truth);
    // World z is up (levelled on the table or the floor, whichever the plane fit takes): the
    // camera's elevation is the true one and its height differs from the truth by a constant.
    const auto elevation = [](const Pose& pose) { return (pose.linear() * Eigen::Vector3d::UnitZ()).z(); };
    EXPECT_NEAR(elevation(*without[i].camera_to_world), elevation(frames[i].truth), 0.02);
    EXPECT_NEAR(without[i].camera_to_world->translation().z() - frames[i].truth.translation().z(),
                without[0].camera_to_world->translation().z() - frames[0].truth.translation().z(), 0.01);
  }
  EXPECT_LT(absolute_trajectory_error(estimate, truth), 0.005);
}

// Anchor stability: an object placed in the tracked world (where a user places it, on the first
// frame) projects where the same object in the true world does, on every frame. Measured on the
// 2-degree orbit at 320x240: median 0.22 px, worst 0.86 px.
TEST(CameraTrackingStage, AnObjectPlacedInTheTrackedWorldStaysWithinAPixelOfItsTruePlace) {
  PinholeIntrinsics intrinsics;
  const auto frames = render(synth::Trajectory::Orbit, 24, 3, intrinsics);
  CameraTrackingOptions odometry;
  odometry.source = PoseSource::Odometry;
  odometry.odometry = options_for_320x240();
  const auto tracked = run_tracking(frames, intrinsics, false, odometry);
  ASSERT_EQ(tracked.size(), frames.size());
  // The tracked world in the true one, fixed by the first frame.
  const Pose tracked_to_true = frames[0].truth * tracked[0].camera_to_world->inverse();
  std::vector<Eigen::Vector3d> object;  // corners of a 10 cm cube on the table, and its centre
  for (int corner = 0; corner < 9; ++corner) {
    const Eigen::Vector3d offset = corner == 8 ? Eigen::Vector3d(0.05, 0.05, 0.05)
                                               : Eigen::Vector3d(corner & 1, (corner >> 1) & 1, (corner >> 2) & 1) * 0.1;
    object.push_back(Eigen::Vector3d(0.3, -0.25, 0.75) + offset);
  }
  std::vector<double> offsets;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    double worst = 0;
    for (const Eigen::Vector3d& world : object) {
      const Eigen::Vector3d in_tracked = tracked_to_true.inverse() * world;
      const Eigen::Vector2d seen = intrinsics.project(tracked[i].camera_to_world->inverse() * in_tracked);
      const Eigen::Vector2d truth = intrinsics.project(frames[i].truth.inverse() * world);
      worst = std::max(worst, (seen - truth).norm());
    }
    offsets.push_back(worst);
  }
  std::sort(offsets.begin(), offsets.end());
  std::printf("anchor offset at 320x240: median %.3f px, worst %.3f px\n", offsets[offsets.size() / 2], offsets.back());
  EXPECT_LE(offsets[offsets.size() / 2], 0.5);  // 1 px at 640x480
  EXPECT_LE(offsets.back(), 1.0);
}

TEST(CameraTrackingStage, SequenceWithoutPosesAndMarkerWithoutLayoutAreErrors) {
  PinholeIntrinsics intrinsics;
  const auto frames = render(synth::Trajectory::Static, 1, 1, intrinsics);
  CameraTrackingOptions sequence;
  sequence.source = PoseSource::Sequence;
  EXPECT_THROW(run_tracking(frames, intrinsics, false, sequence), Error);
  CameraTrackingOptions marker;
  marker.source = PoseSource::Marker;
  EXPECT_THROW(CameraTrackingStage{marker}, Error);
  EXPECT_EQ(parse_named(kPoseSourceNames, "--pose", "marker+odometry"), PoseSource::MarkerOdometry);
  EXPECT_EQ(parse_named(kPoseSourceNames, "--pose", "auto"), std::nullopt);
  EXPECT_THROW((void)parse_named(kPoseSourceNames, "--pose", "gps"), Error);
  EXPECT_STREQ(to_string(PoseSource::MarkerOdometry), "marker+odometry");
}

}  // namespace
}  // namespace relight::capture
