#include "relight/core/pose.h"

#include <gtest/gtest.h>

#include <numbers>

namespace relight {
namespace {

TEST(Pose, TumFieldsRoundTrip) {
  const std::array<double, 7> fields{1.3047, 0.6853, 1.5750, 0.6853, 0.5405, -0.0074, -0.4881};
  const Pose pose = pose_from_tum(fields);
  const auto back = pose_to_tum(pose);
  const double norm = std::sqrt(0.6853 * 0.6853 + 0.5405 * 0.5405 + 0.0074 * 0.0074 + 0.4881 * 0.4881);
  // qw was negative: the same rotation comes back with the sign flipped.
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(back[i], fields[i], 1e-12);
  for (int i = 3; i < 7; ++i) EXPECT_NEAR(back[i], -fields[i] / norm, 1e-9);
  EXPECT_NEAR(rotation_distance(pose, pose_from_tum(back)), 0.0, 1e-7);
}

// A quaternion is a direction: any positive scale gives the same rotation, including scales whose
// squared norm a double cannot hold (a ground-truth file with components around 1e300 became the
// identity before).
TEST(Pose, TumQuaternionOfAnyScaleGivesTheSameRotation) {
  const std::array<double, 7> unit{0.1, 0.2, 0.3, 0.6853, 0.5405, -0.0074, -0.4881};
  const Pose reference = pose_from_tum(unit);
  for (const double scale : {1e-150, 1e-3, 7.0, 1e160, 1e300}) {
    std::array<double, 7> scaled = unit;
    for (int i = 3; i < 7; ++i) scaled[static_cast<std::size_t>(i)] *= scale;
    EXPECT_NEAR(rotation_distance(pose_from_tum(scaled), reference), 0.0, 1e-9) << "scale " << scale;
  }
  EXPECT_GT(rotation_distance(reference, Pose::Identity()), 1.0);
}

TEST(Pose, InterpolationIsLinearInTranslationAndSlerpInRotation) {
  Pose a = Pose::Identity();
  Pose b = Pose::Identity();
  b.linear() = Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  b.translation() = Eigen::Vector3d(2, 0, -4);
  const Pose mid = interpolate(a, b, 0.5);
  EXPECT_NEAR((mid.translation() - Eigen::Vector3d(1, 0, -2)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(rotation_distance(a, mid), std::numbers::pi / 4, 1e-9);
  EXPECT_NEAR(rotation_distance(mid, b), std::numbers::pi / 4, 1e-9);
  EXPECT_NEAR(rotation_distance(interpolate(a, b, 1.0), b), 0.0, 1e-7);
}

}  // namespace
}  // namespace relight
