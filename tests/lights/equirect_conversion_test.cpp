#include <gtest/gtest.h>

#include "probes.h"
#include "relight/lights/probe_geometry.h"

namespace relight::lights {
namespace {

using namespace test;

// A smooth sky brighter towards world +z, plus a small bright disc at 40 degrees from the zenith.
Eigen::Vector3d sky(const Eigen::Vector3d& d) { return Eigen::Vector3d(1.0 + d.z(), 0.5, 2.0 - d.z()); }
const Eigen::Vector3d kEmitter = spherical(radians(40.0), radians(120.0));

TEST(EquirectToFisheye, ResampledRadianceFollowsTheSourceDirections) {
  const ProbeGeometry latlong(ProbeCalibration::equirectangular(), 512, 256);
  const RadianceImage source = analytic_probe(latlong, [](const Eigen::Vector3d& d) -> Eigen::Vector3d {
    return angle_between(d, kEmitter) < radians(3.0) ? Eigen::Vector3d::Constant(500.0) : sky(d);
  });
  const ProbeCalibration fisheye_calibration = ProbeCalibration::centred_fisheye(128, 128);
  const ProbeGeometry fisheye(fisheye_calibration, 128, 128);
  const RadianceImage converted =
      equirectangular_to_fisheye(source, Eigen::Matrix3d::Identity(), fisheye_calibration.fisheye,
                                 fisheye_calibration.probe_to_world);
  ASSERT_EQ(converted.width(), 128);

  int checked = 0;
  for (int row = 0; row < 128; ++row) {
    for (int col = 0; col < 128; ++col) {
      const auto d = fisheye.direction(col, row);
      const bool fully_outside = !fisheye.direction(col - 0.5, row - 0.5) && !fisheye.direction(col + 0.5, row - 0.5) &&
                                 !fisheye.direction(col - 0.5, row + 0.5) && !fisheye.direction(col + 0.5, row + 0.5);
      if (fully_outside) {
        EXPECT_EQ(converted(row, col), Float3{}) << row << "," << col;
      }
      if (!d) continue;  // rim pixels straddling the circle hold partial coverage
      if (angle_between(*d, kEmitter) < radians(6.0) || d->z() < 0.05) continue;  // disc edge, rim
      const Eigen::Vector3d expected = sky(*d);
      EXPECT_NEAR(converted(row, col).x, expected.x(), 0.03) << row << "," << col;
      EXPECT_NEAR(converted(row, col).z, expected.z(), 0.03) << row << "," << col;
      ++checked;
    }
  }
  EXPECT_GT(checked, 10000);

  // The brightest fisheye pixel looks at the emitter.
  int best_row = 0, best_col = 0;
  for (int row = 0; row < 128; ++row) {
    for (int col = 0; col < 128; ++col) {
      if (converted(row, col).x > converted(best_row, best_col).x) best_row = row, best_col = col;
    }
  }
  EXPECT_LT(degrees(angle_between(*fisheye.direction(best_col, best_row), kEmitter)), 3.0);
}

}  // namespace
}  // namespace relight::lights
