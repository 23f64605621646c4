#include "relight/core/camera.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace relight {
namespace {

TEST(PinholeIntrinsics, ProjectUnprojectRoundTrip) {
  const auto k = PinholeIntrinsics::kinect_v1();
  EXPECT_DOUBLE_EQ(k.fx, 525.0);
  EXPECT_DOUBLE_EQ(k.cx, 319.5);
  for (double u : {0.0, 100.25, 319.5, 639.0}) {
    for (double v : {0.0, 239.5, 479.0}) {
      for (double z : {0.5, 1.7, 4.0}) {
        const Eigen::Vector3d p = k.unproject(u, v, z);
        EXPECT_NEAR(p.z(), z, 1e-12);
        const Eigen::Vector2d uv = k.project(p);
        EXPECT_NEAR(uv.x(), u, 1e-9);
        EXPECT_NEAR(uv.y(), v, 1e-9);
      }
    }
  }
}

TEST(PinholeIntrinsics, PrincipalPointLiesOnTheOpticalAxis) {
  const auto k = *PinholeIntrinsics::preset("fr1");
  const Eigen::Vector3d p = k.unproject(k.cx, k.cy, 2.0);
  EXPECT_NEAR(p.x(), 0.0, 1e-12);
  EXPECT_NEAR(p.y(), 0.0, 1e-12);
  EXPECT_FALSE(PinholeIntrinsics::preset("fr9").has_value());
  EXPECT_DOUBLE_EQ(PinholeIntrinsics::preset("fr3")->fy, 539.2);
}

TEST(FisheyeCamera, EquidistantMappingAndRoundTrip) {
  FisheyeCamera fisheye;
  // Straight ahead maps to the centre; 90 degrees maps to the rim.
  EXPECT_NEAR((*fisheye.project({0, 0, 1}) - Eigen::Vector2d(fisheye.cx, fisheye.cy)).norm(), 0.0, 1e-12);
  const Eigen::Vector2d rim = *fisheye.project({1, 0, 0});
  EXPECT_NEAR(rim.x() - fisheye.cx, fisheye.radius, 1e-9);
  // 45 degrees lands at half the radius (r = f * theta).
  const Eigen::Vector2d half = *fisheye.project(Eigen::Vector3d(0, 1, 1).normalized());
  EXPECT_NEAR(half.y() - fisheye.cy, fisheye.radius / 2, 1e-9);
  EXPECT_FALSE(fisheye.project({0, 0, -1}).has_value());
  for (double u : {100.0, 200.0, 255.5, 400.0}) {
    for (double v : {150.0, 255.5, 300.0}) {
      const auto d = fisheye.unproject(u, v);
      ASSERT_TRUE(d.has_value());
      EXPECT_NEAR(d->norm(), 1.0, 1e-12);
      const auto uv = fisheye.project(*d);
      EXPECT_NEAR(uv->x(), u, 1e-9);
      EXPECT_NEAR(uv->y(), v, 1e-9);
    }
  }
  EXPECT_FALSE(fisheye.unproject(0, 0).has_value());  // corner, outside the image circle
}

TEST(FisheyeCamera, PixelSolidAnglesSumToTheHemisphere) {
  FisheyeCamera fisheye;
  double total = 0;
  for (int v = 0; v < fisheye.height; ++v) {
    for (int u = 0; u < fisheye.width; ++u) total += fisheye.pixel_solid_angle(u, v);
  }
  EXPECT_NEAR(total, 2 * std::numbers::pi, 2 * std::numbers::pi * 0.01);
}

}  // namespace
}  // namespace relight
