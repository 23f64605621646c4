#include "relight/synth/raycast.h"

#include <gtest/gtest.h>

#include <cmath>

#include "relight/synth/trajectory.h"

namespace relight::synth {
namespace {

using Eigen::Vector3d;

struct StaticView {
  Scene scene = default_indoor_scene();
  PinholeIntrinsics intrinsics = PinholeIntrinsics::kinect_v1();
  Pose pose = make_trajectory(Trajectory::Static, 1, 0, scene).front();
  RenderedFrame frame = render_frame(scene, intrinsics, pose, 0);

  [[nodiscard]] Vector3d ray_world(int row, int col) const {
    return pose.linear() * intrinsics.ray(col, row).normalized();
  }
  [[nodiscard]] Vector3d point_world(int row, int col) const {
    return pose * intrinsics.unproject(col, row, frame.depth(row, col));
  }
  [[nodiscard]] bool shows(int row, int col, const std::string& material) const {
    return frame.material(row, col) == scene.material_index(material) + 1;
  }
};

const StaticView& view() {
  static const StaticView v;
  return v;
}

// Depth along the optical axis from a distance along the unit ray (closed form in the test).
double depth_from_t(const StaticView& v, int row, int col, double t) {
  return t * v.intrinsics.ray(col, row).normalized().z();
}

TEST(Raycast, DepthOnTheFloorAndTableTopMatchesTheClosedFormPlaneIntersection) {
  const StaticView& v = view();
  const Vector3d o = v.pose.translation();
  int floor_pixels = 0, table_pixels = 0;
  for (int row = 0; row < v.intrinsics.height; ++row) {
    for (int col = 0; col < v.intrinsics.width; ++col) {
      const Vector3d d = v.ray_world(row, col);
      double plane_z = -1.0;
      if (v.shows(row, col, "floor")) plane_z = 0.0, ++floor_pixels;
      if (v.shows(row, col, "tag_black") || v.shows(row, col, "tag_white")) plane_z = 0.75, ++table_pixels;
      if (plane_z < 0.0) continue;
      const double t = (plane_z - o.z()) / d.z();
      ASSERT_NEAR(v.frame.depth(row, col), depth_from_t(v, row, col, t), 2e-6 * t) << row << "," << col;
    }
  }
  EXPECT_GT(floor_pixels, 5000);
  EXPECT_GT(table_pixels, 500);
}

TEST(Raycast, DepthOnTheSphereMatchesTheClosedFormSphereIntersection) {
  const StaticView& v = view();
  const Vector3d centre{-0.35, 0.20, 0.85};
  const double radius = 0.10;
  const Vector3d o = v.pose.translation();
  int pixels = 0;
  for (int row = 0; row < v.intrinsics.height; ++row) {
    for (int col = 0; col < v.intrinsics.width; ++col) {
      if (!v.shows(row, col, "glossy_blue")) continue;
      const Vector3d d = v.ray_world(row, col);
      const double b = (o - centre).dot(d), c = (o - centre).squaredNorm() - radius * radius;
      ASSERT_GE(b * b - c, 0.0);
      const double t = -b - std::sqrt(b * b - c);
      ASSERT_NEAR(v.frame.depth(row, col), depth_from_t(v, row, col, t), 1e-5) << row << "," << col;
      ++pixels;
    }
  }
  EXPECT_GT(pixels, 500);
  // And the pixel at the projected sphere centre sees the sphere.
  const Eigen::Vector2d centre_px = v.intrinsics.project(v.pose.inverse() * centre);
  EXPECT_TRUE(v.shows(static_cast<int>(std::lround(centre_px.y())), static_cast<int>(std::lround(centre_px.x())),
                      "glossy_blue"));
}

TEST(Raycast, UnprojectedDepthLiesOnTheKnownSurfaces) {
  const StaticView& v = view();
  const Vector3d centre{-0.35, 0.20, 0.85};
  int checked = 0;
  for (int row = 0; row < v.intrinsics.height; row += 2) {
    for (int col = 0; col < v.intrinsics.width; col += 2) {
      const Vector3d p = v.point_world(row, col);
      double distance = -1.0;
      if (v.shows(row, col, "glossy_blue")) distance = std::abs((p - centre).norm() - 0.10);
      if (v.shows(row, col, "floor")) distance = std::abs(p.z());
      if (v.shows(row, col, "tag_white")) distance = std::abs(p.z() - 0.75);
      if (v.shows(row, col, "wall")) distance = 2.5 - std::max(std::abs(p.x()), std::abs(p.y()));
      if (distance < 0.0) continue;
      ASSERT_LT(distance, 1e-4) << row << "," << col;
      ++checked;
    }
  }
  EXPECT_GT(checked, 20000);
}

TEST(Raycast, NormalsAreUnitAndFaceTheCamera) {
  const StaticView& v = view();
  int valid = 0;
  for (int row = 0; row < v.intrinsics.height; row += 3) {
    for (int col = 0; col < v.intrinsics.width; col += 3) {
      const Float3 n = v.frame.normals(row, col);
      if (!is_valid_depth(v.frame.depth(row, col))) {
        EXPECT_FALSE(is_valid_normal(n));
        continue;
      }
      ++valid;
      EXPECT_NEAR(length(n), 1.0f, 1e-5f);
      const Vector3d ray = v.intrinsics.ray(col, row);
      EXPECT_LT(ray.dot(Vector3d(n.x, n.y, n.z)), 0.0);
    }
  }
  EXPECT_GT(valid, 30000);
  // The floor's normal is world up, seen in the camera frame.
  const Vector3d up_camera = v.pose.linear().transpose() * Vector3d::UnitZ();
  for (int row = 0; row < v.intrinsics.height; ++row) {
    for (int col = 0; col < v.intrinsics.width; ++col) {
      if (!v.shows(row, col, "floor")) continue;
      const Float3 n = v.frame.normals(row, col);
      ASSERT_NEAR(Vector3d(n.x, n.y, n.z).dot(up_camera), 1.0, 1e-6);
    }
  }
}

TEST(Raycast, AlbedoAndMaterialIdsAgree) {
  const StaticView& v = view();
  for (int row = 0; row < v.intrinsics.height; row += 4) {
    for (int col = 0; col < v.intrinsics.width; col += 4) {
      const int id = v.frame.material(row, col);
      const Float3 a = v.frame.albedo(row, col);
      if (id == 0) {
        EXPECT_EQ(a, Float3{});
        continue;
      }
      const Vector3d kd = v.scene.materials[static_cast<std::size_t>(id - 1)].kd;
      ASSERT_NEAR(a.x, kd.x(), 1e-6);
      ASSERT_NEAR(a.z, kd.z(), 1e-6);
    }
  }
}

TEST(Raycast, BoxAndCylinderIntersectionsAreExact) {
  const Ray down{{0.1, 0.2, 5.0}, {0, 0, -1}};
  const auto box = intersect(Shape{Box{{-1, -1, 0}, {1, 1, 2}}}, down, 0.0, 100.0);
  ASSERT_TRUE(box);
  EXPECT_DOUBLE_EQ(box->t, 3.0);
  EXPECT_EQ(box->normal, Vector3d::UnitZ());
  const Ray sideways{{-5.0, 0.0, 0.5}, {1, 0, 0}};
  const auto cylinder = intersect(Shape{Cylinder{{0, 0, 0}, 0.25, 1.0}}, sideways, 0.0, 100.0);
  ASSERT_TRUE(cylinder);
  EXPECT_NEAR(cylinder->t, 4.75, 1e-12);
  EXPECT_NEAR(cylinder->normal.x(), -1.0, 1e-12);
  const auto cap = intersect(Shape{Cylinder{{0, 0, 0}, 0.25, 1.0}}, Ray{{0.1, 0.0, 3.0}, {0, 0, -1}}, 0.0, 100.0);
  ASSERT_TRUE(cap);
  EXPECT_NEAR(cap->t, 2.0, 1e-12);
  EXPECT_FALSE(intersect(Shape{Cylinder{{0, 0, 0}, 0.25, 1.0}}, Ray{{0.3, 0.0, 3.0}, {0, 0, -1}}, 0.0, 100.0));
  EXPECT_FALSE(intersect(Shape{Box{{-1, -1, 0}, {1, 1, 2}}}, down, 0.0, 2.5));
}

TEST(Raycast, FloorUnderTheTableIsInShadowAndOpenFloorIsLit) {
  const Scene scene = default_indoor_scene();
  for (const PointLight& light : scene.lights) {
    EXPECT_TRUE(occluded(scene, {0.0, 0.0, 1e-6}, light.position));
    EXPECT_FALSE(occluded(scene, {1.5, -1.5, 1e-6}, light.position));
  }
  const Material& floor = scene.materials[static_cast<std::size_t>(scene.material_index("floor"))];
  const Vector3d lit = shade(scene, {1.5, -1.5, 0}, Vector3d::UnitZ(), floor, Vector3d(1, -1, 1).normalized());
  const Vector3d dark = shade(scene, {0, 0, 0}, Vector3d::UnitZ(), floor, Vector3d(1, -1, 1).normalized());
  EXPECT_NEAR(dark.x(), floor.kd.x() * scene.environment.x(), 1e-12);  // ambient only
  EXPECT_GT(lit.x(), 2.0 * dark.x());
}

TEST(Raycast, GlossySphereShowsASpecularHighlight) {
  const StaticView& v = view();
  const Material& blue = v.scene.materials[static_cast<std::size_t>(v.scene.material_index("glossy_blue"))];
  double brightest = 0.0;
  for (int row = 0; row < v.intrinsics.height; ++row) {
    for (int col = 0; col < v.intrinsics.width; ++col) {
      if (v.shows(row, col, "glossy_blue")) brightest = std::max(brightest, double(v.frame.radiance(row, col).x));
    }
  }
  // Diffuse red alone cannot exceed kd_r * (L_env + sum E / pi) with E <= I / d^2 ~ 3.5.
  EXPECT_GT(brightest, blue.kd.x() * (0.15 + 3.5 / 3.14159) * 3.0);
}

TEST(Raycast, OutputDoesNotDependOnTheThreadCount) {
  const Scene scene = default_indoor_scene();
  PinholeIntrinsics small{131.25, 131.25, 79.5, 59.5, 160, 120};
  const Pose pose = make_trajectory(Trajectory::Static, 1, 0, scene).front();
  const RenderedFrame one = render_frame(scene, small, pose, 1);
  const RenderedFrame three = render_frame(scene, small, pose, 3);
  EXPECT_TRUE(one.depth == three.depth);
  EXPECT_TRUE(one.radiance == three.radiance);
  EXPECT_TRUE(one.material == three.material);
}

TEST(Raycast, ColorEncodingAppliesGainsExposureAndSrgb) {
  RadianceImage radiance(2, 1, Float3{0.2f, 0.2f, 0.2f});
  radiance(0, 1) = {5.f, 0.f, 0.0031308f};
  const ColorImage plain = encode_color(radiance);
  EXPECT_EQ(plain(0, 0).r, std::lround(255.0 * (1.055 * std::pow(0.2, 1 / 2.4) - 0.055)));
  EXPECT_EQ(plain(0, 1), (Rgb8{255, 0, 10}));
  const ColorImage warm = encode_color(radiance, ColorResponse{{1.5, 1.0, 0.5}, 1.0});
  EXPECT_GT(warm(0, 0).r, plain(0, 0).r);
  EXPECT_EQ(warm(0, 0).g, plain(0, 0).g);
  EXPECT_LT(warm(0, 0).b, plain(0, 0).b);
  const ColorImage bright = encode_color(radiance, ColorResponse{{1, 1, 1}, 2.0});
  EXPECT_EQ(bright(0, 0).g, encode_color(RadianceImage(1, 1, Float3{0.4f, 0.4f, 0.4f}))(0, 0).g);
  EXPECT_NEAR(srgb_decode(srgb_encode(0.37)), 0.37, 1e-12);
}

}  // namespace
}  // namespace relight::synth
