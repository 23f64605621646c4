#include "relight/synth/trajectory.h"

#include <gtest/gtest.h>

#include "relight/core/error.h"

namespace relight::synth {
namespace {

using Eigen::Vector3d;

TEST(Trajectory, ParsesNamesAndRejectsOthers) {
  EXPECT_EQ(parse_trajectory("static"), Trajectory::Static);
  EXPECT_EQ(parse_trajectory("orbit"), Trajectory::Orbit);
  EXPECT_EQ(parse_trajectory("handheld"), Trajectory::Handheld);
  EXPECT_THROW((void)parse_trajectory("circle"), Error);
  EXPECT_STREQ(to_string(Trajectory::Handheld), "handheld");
}

TEST(Trajectory, TimestampsStartAtOneSecondAtThirtyHertz) {
  EXPECT_DOUBLE_EQ(frame_timestamp(0), 1.0);
  EXPECT_DOUBLE_EQ(frame_timestamp(30), 2.0);
  EXPECT_NEAR(frame_timestamp(1), 1.0 + 1.0 / 30.0, 1e-15);
}

TEST(Trajectory, LookAtPutsTheTargetOnTheOpticalAxisWithImageDownTowardsTheFloor) {
  const Pose pose = look_at({2, -1, 1.5}, {0, 0, 0.75});
  const Vector3d target_camera = pose.inverse() * Vector3d{0, 0, 0.75};
  EXPECT_NEAR(target_camera.x(), 0.0, 1e-12);
  EXPECT_NEAR(target_camera.y(), 0.0, 1e-12);
  EXPECT_GT(target_camera.z(), 0.0);
  EXPECT_GT((pose.linear() * Vector3d::UnitY()).dot(-Vector3d::UnitZ()), 0.0);  // camera y points down
  EXPECT_NEAR(pose.linear().determinant(), 1.0, 1e-12);
}

TEST(Trajectory, OrbitCirclesTheTableAndKeepsItCentred) {
  const Scene scene = default_indoor_scene();
  const auto poses = make_trajectory(Trajectory::Orbit, 90, 0, scene);
  ASSERT_EQ(poses.size(), 90u);
  for (const Pose& pose : poses) {
    const Vector3d eye = pose.translation() - scene.look_at;
    EXPECT_NEAR(std::hypot(eye.x(), eye.y()), 1.5, 1e-9);
    const Vector3d target = pose.inverse() * scene.look_at;
    EXPECT_NEAR(target.x(), 0.0, 1e-9);
    EXPECT_NEAR(target.y(), 0.0, 1e-9);
  }
  EXPECT_NEAR(rotation_distance(poses.front(), poses.back()), 89.0 / 30.0 * 20.0 * 3.14159265 / 180.0, 1e-3);
  const auto still = make_trajectory(Trajectory::Static, 5, 0, scene);
  EXPECT_TRUE(still.front().isApprox(still.back()));
  EXPECT_TRUE(still.front().isApprox(poses.front()));
}

TEST(Trajectory, HandheldIsSmoothSeededAndDeterministic) {
  const Scene scene = default_indoor_scene();
  const auto a = make_trajectory(Trajectory::Handheld, 120, 3, scene);
  const auto b = make_trajectory(Trajectory::Handheld, 120, 3, scene);
  const auto c = make_trajectory(Trajectory::Handheld, 120, 4, scene);
  double max_step = 0.0, max_rotation_step = 0.0, max_offset = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_TRUE(a[i].isApprox(b[i], 0.0));
    if (i == 0) continue;
    max_step = std::max(max_step, (a[i].translation() - a[i - 1].translation()).norm());
    max_rotation_step = std::max(max_rotation_step, rotation_distance(a[i - 1], a[i]));
    max_offset = std::max(max_offset, (a[i].translation() - c[i].translation()).norm());
  }
  EXPECT_LT(max_step, 0.03);           // < 0.9 m/s
  EXPECT_LT(max_rotation_step, 0.03);  // < 50 deg/s
  EXPECT_GT(max_offset, 0.01);         // another seed shakes differently
  const Vector3d target = a.back().inverse() * scene.look_at;
  EXPECT_LT(std::hypot(target.x(), target.y()) / target.z(), 0.2);  // still looking at the table
}

}  // namespace
}  // namespace relight::synth
