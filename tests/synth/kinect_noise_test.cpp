#include "relight/synth/kinect_noise.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "relight/core/error.h"
#include "relight/synth/raycast.h"
#include "relight/synth/trajectory.h"

namespace relight::synth {
namespace {

using Eigen::Vector3d;

// A large wall facing the camera at distance z (camera frame = world frame).
RenderedFrame fronto_parallel_plane(double z) {
  Scene scene;
  scene.materials = {{{{0.5, 0.5, 0.5}, 0.0, 1.0}, "grey"}};
  scene.objects.push_back({"wall", Rect{{0, 0, z}, -Vector3d::UnitZ(), Vector3d::UnitX(), Vector3d::UnitY(), 50, 50}, 0});
  return render_frame(scene, PinholeIntrinsics::kinect_v1(), Pose::Identity(), 0);
}

struct Stats {
  double mean = 0, sigma = 0;
  int count = 0;
};

Stats error_stats(const DepthMap& noisy, const DepthMap& truth) {
  double sum = 0, sum2 = 0;
  int n = 0;
  for (std::size_t i = 0; i < noisy.size(); ++i) {
    if (!is_valid_depth(noisy.pixels()[i])) continue;
    const double e = double(noisy.pixels()[i]) - double(truth.pixels()[i]);
    sum += e, sum2 += e * e, ++n;
  }
  const double mean = sum / n;
  return {mean, std::sqrt(sum2 / n - mean * mean), n};
}

TEST(KinectNoise, AxialSigmaFollowsNguyenEtAlOnAFrontoParallelPlane) {
  EXPECT_NEAR(kinect_axial_sigma(1.0), 0.0012 + 0.0019 * 0.36, 1e-15);
  KinectNoiseOptions options;
  options.quantise = false;  // isolate the axial term
  for (double z : {1.0, 3.0}) {
    const RenderedFrame plane = fronto_parallel_plane(z);
    const Stats stats = error_stats(apply_kinect_noise(plane.depth, plane.normals, PinholeIntrinsics::kinect_v1(),
                                                       options, 7, 0),
                                    plane.depth);
    EXPECT_GT(stats.count, 300000);
    EXPECT_NEAR(stats.sigma, kinect_axial_sigma(z), 0.15 * kinect_axial_sigma(z)) << "z = " << z;
    EXPECT_NEAR(stats.mean, 0.0, 0.05 * kinect_axial_sigma(z));
  }
}

TEST(KinectNoise, QuantisationAddsTheVarianceOfTheDisparityStep) {
  const KinectNoiseOptions options;
  for (double z : {1.0, 3.0}) {
    const RenderedFrame plane = fronto_parallel_plane(z);
    const Stats stats = error_stats(
        apply_kinect_noise(plane.depth, plane.normals, PinholeIntrinsics::kinect_v1(), options, 7, 0), plane.depth);
    // A disparity step of 1/8 px is a depth step of z^2 / (b f) / 8; rounding adds step^2 / 12.
    const double step = z * z / (0.075 * 580.0) / 8.0;
    const double expected = std::sqrt(std::pow(kinect_axial_sigma(z), 2) + step * step / 12.0);
    EXPECT_NEAR(stats.sigma, expected, 0.15 * expected) << "z = " << z;
    EXPECT_GT(stats.sigma, 1.05 * kinect_axial_sigma(z));  // quantisation really is on
  }
}

TEST(KinectNoise, QuantisedDepthsLieOnTheDisparityGrid) {
  const RenderedFrame plane = fronto_parallel_plane(2.2);
  const DepthMap noisy = apply_kinect_noise(plane.depth, plane.normals, PinholeIntrinsics::kinect_v1(), {}, 3, 1);
  int distinct_steps = 0;
  double previous = -1.0;
  for (int col = 0; col < noisy.width(); ++col) {
    const double z = noisy(240, col);
    ASSERT_TRUE(is_valid_depth(static_cast<float>(z)));
    const double eighths = 0.075 * 580.0 / z * 8.0;
    ASSERT_NEAR(eighths, std::round(eighths), 2e-4 * eighths) << col;  // float storage only
    if (std::abs(z - previous) > 1e-6) ++distinct_steps;
    previous = z;
  }
  EXPECT_GT(distinct_steps, 10);
  EXPECT_NEAR(quantise_depth(2.2, {}), 0.075 * 580.0 / (std::round(0.075 * 580.0 / 2.2 * 8.0) / 8.0), 1e-12);
}

TEST(KinectNoise, NoDepthBelowHalfAMetreOrBeyondFourMetres) {
  for (double z : {0.45, 4.2}) {
    const RenderedFrame plane = fronto_parallel_plane(z);
    const DepthMap noisy = apply_kinect_noise(plane.depth, plane.normals, PinholeIntrinsics::kinect_v1(), {}, 1, 0);
    int valid = 0;
    for (float d : noisy.pixels()) valid += is_valid_depth(d) ? 1 : 0;
    EXPECT_LT(valid, 20) << "z = " << z;  // only the noise tail may cross into range
  }
  const Scene scene = default_indoor_scene();
  const PinholeIntrinsics k = PinholeIntrinsics::kinect_v1();
  const RenderedFrame frame = render_frame(scene, k, make_trajectory(Trajectory::Static, 1, 0, scene).front(), 0);
  const DepthMap noisy = apply_kinect_noise(frame.depth, frame.normals, k, {}, 1, 0);
  int valid = 0, beyond = 0;
  for (std::size_t i = 0; i < noisy.size(); ++i) {
    const float d = noisy.pixels()[i];
    beyond += frame.depth.pixels()[i] > 4.2f ? 1 : 0;
    if (!is_valid_depth(d)) continue;
    ++valid;
    ASSERT_GE(d, 0.5f);
    ASSERT_LE(d, 4.0f);
  }
  EXPECT_GT(valid, 200000);
  EXPECT_GT(beyond, 0);  // the far wall really is out of range in this view
}

TEST(KinectNoise, GrazingAnglesDropOut) {
  // A floor seen from 0.3 m above, looking level: the angle to the normal grows towards the horizon.
  Scene scene;
  scene.materials = {{{{0.5, 0.5, 0.5}, 0.0, 1.0}, "grey"}};
  scene.objects.push_back({"floor", Rect{{0, 0, 0}, Vector3d::UnitZ(), Vector3d::UnitX(), Vector3d::UnitY(), 50, 50}, 0});
  const PinholeIntrinsics k = PinholeIntrinsics::kinect_v1();
  const Pose pose = look_at({0, 0, 0.3}, {0, 3, 0.0});
  const RenderedFrame frame = render_frame(scene, k, pose, 0);
  KinectNoiseOptions options;
  options.edge_dropouts = false;
  const DepthMap noisy = apply_kinect_noise(frame.depth, frame.normals, k, options, 5, 0);
  int steep = 0, steep_valid = 0, moderate = 0, moderate_valid = 0;
  for (int row = 0; row < k.height; ++row) {
    for (int col = 0; col < k.width; ++col) {
      const float z = frame.depth(row, col);
      if (!is_valid_depth(z) || z > 3.5f || z < 0.6f) continue;  // stay inside the sensor's range
      const Float3 n = frame.normals(row, col);
      const double cosine = std::abs(k.ray(col, row).normalized().dot(Vector3d(n.x, n.y, n.z)));
      const double angle = std::acos(cosine) * 180.0 / std::numbers::pi;
      const bool valid = is_valid_depth(noisy(row, col));
      if (angle > 75.5) ++steep, steep_valid += valid ? 1 : 0;
      if (angle < 74.0) ++moderate, moderate_valid += valid ? 1 : 0;
    }
  }
  EXPECT_GT(steep, 1000);
  EXPECT_EQ(steep_valid, 0);
  EXPECT_GT(moderate, 1000);
  EXPECT_GT(moderate_valid, 0.99 * moderate);
}

TEST(KinectNoise, DepthDiscontinuitiesDropOut) {
  const Scene scene = default_indoor_scene();
  const PinholeIntrinsics k = PinholeIntrinsics::kinect_v1();
  const RenderedFrame frame = render_frame(scene, k, make_trajectory(Trajectory::Static, 1, 0, scene).front(), 0);
  const DepthMap noisy = apply_kinect_noise(frame.depth, frame.normals, k, {}, 9, 0);
  int edge = 0, edge_valid = 0;
  for (int row = 1; row + 1 < k.height; ++row) {
    for (int col = 1; col + 1 < k.width; ++col) {
      const float z = frame.depth(row, col);
      if (!is_valid_depth(z) || z > 3.5f) continue;
      // The table's edge against the floor: a jump of more than 0.3 m to the right neighbour.
      if (std::abs(frame.depth(row, col + 1) - z) < 0.3f) continue;
      ++edge, edge_valid += is_valid_depth(noisy(row, col)) ? 1 : 0;
    }
  }
  EXPECT_GT(edge, 200);
  EXPECT_LT(edge_valid, 0.4 * edge);
}

TEST(KinectNoise, SameSeedSameNoiseOtherSeedOrFrameOtherNoise) {
  const RenderedFrame plane = fronto_parallel_plane(1.5);
  const PinholeIntrinsics k = PinholeIntrinsics::kinect_v1();
  const DepthMap a = apply_kinect_noise(plane.depth, plane.normals, k, {}, 11, 4, 1);
  const DepthMap b = apply_kinect_noise(plane.depth, plane.normals, k, {}, 11, 4, 2);
  const DepthMap c = apply_kinect_noise(plane.depth, plane.normals, k, {}, 12, 4, 2);
  const DepthMap d = apply_kinect_noise(plane.depth, plane.normals, k, {}, 11, 5, 2);
  EXPECT_TRUE(a == b);
  EXPECT_FALSE(a == c);
  EXPECT_FALSE(a == d);
}

TEST(KinectNoise, ParsesModelNames) {
  EXPECT_EQ(parse_noise("none"), NoiseModel::None);
  EXPECT_EQ(parse_noise("kinect1"), NoiseModel::Kinect1);
  EXPECT_THROW((void)parse_noise("kinect2"), Error);
  EXPECT_STREQ(to_string(NoiseModel::Kinect1), "kinect1");
}

}  // namespace
}  // namespace relight::synth
