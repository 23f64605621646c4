// The tracked lamp's calibration (--real-spot-tag, --real-spot-tag-offset) and how a tag pose
// places its light; the stage itself runs through `relight replay` in dynamic_light_cli_test.cpp.
#include "tracked_lamp_stage.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "relight/core/error.h"

namespace relight::app {
namespace {

TEST(TrackedLamp, ParsesTheTagTheConeTheIntensityAndTheOffset) {
  const TrackedLamp plain = parse_tracked_lamp("3,0.1,30,2", "");
  EXPECT_EQ(plain.tag_id, 3);
  EXPECT_DOUBLE_EQ(plain.tag_size, 0.1);
  EXPECT_DOUBLE_EQ(plain.cone_degrees, 30.0);
  EXPECT_DOUBLE_EQ(plain.inner_degrees, 24.0);
  EXPECT_EQ(plain.power, Eigen::Vector3d::Constant(2.0));
  EXPECT_EQ(plain.position_in_tag, Eigen::Vector3d::Zero());
  EXPECT_EQ(plain.axis_in_tag, Eigen::Vector3d::UnitZ());
  const TrackedLamp full = parse_tracked_lamp("0,0.16,25,3,1,0.5,0.25", "0,0.1,0,0,3,4");
  EXPECT_EQ(full.power, Eigen::Vector3d(3.0, 1.5, 0.75));
  EXPECT_EQ(full.position_in_tag, Eigen::Vector3d(0, 0.1, 0));
  EXPECT_NEAR((full.axis_in_tag - Eigen::Vector3d(0, 0.6, 0.8)).norm(), 0.0, 1e-12);
  for (const char* bad :
       {"", "1,0.1,30", "1,0.1,30,2,1", "-1,0.1,30,2", "1,-0.1,30,2", "1,0.1,0,2", "1,0.1,30,-2", "x,0.1,30,2"}) {
    EXPECT_THROW((void)parse_tracked_lamp(bad, ""), Error) << bad;
  }
  for (const char* bad : {"0,0", "0,0,0,1", "0,0,0,0,0,0", "0,0,nan"}) {
    EXPECT_THROW((void)parse_tracked_lamp("1,0.1,30,2", bad), Error) << bad;
  }
}

TEST(TrackedLamp, TheTagsPoseCarriesTheLightsPositionAndAxis) {
  const TrackedLamp lamp = parse_tracked_lamp("1,0.16,25,3", "0,0.12,0,0,0,1");
  Pose tag_to_world = Pose::Identity();
  tag_to_world.linear() = Eigen::AngleAxisd(0.5 * EIGEN_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  tag_to_world.translation() = Eigen::Vector3d(1, 2, 3);
  const lights::Light light = lamp_light(lamp, tag_to_world);
  EXPECT_EQ(light.kind, lights::LightKind::Spot);
  EXPECT_TRUE(light.real);
  // Tag y (0.12 m) turns into world z; tag z into world -y.
  EXPECT_NEAR((light.position - Eigen::Vector3d(1, 2, 3.12)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((light.axis - Eigen::Vector3d(0, -1, 0)).norm(), 0.0, 1e-12);
  EXPECT_DOUBLE_EQ(light.cone_degrees, 25.0);
  EXPECT_DOUBLE_EQ(light.inner_degrees, 20.0);
}

// A probe inside the lamp's cone saw the lamp: the probe's lights towards it (within
// kLampInProbeDegrees) are the lamp's and are taken out, with their irradiance; others stay.
// Outside the cone the probe saw no lamp and keeps every light.
TEST(TrackedLamp, TheProbesLightsTowardsTheLampAreTakenOutWhereTheLampShinesOnTheProbe) {
  lights::Light lamp;
  lamp.kind = lights::LightKind::Spot;
  lamp.position = Eigen::Vector3d(0, 0, 1);
  lamp.axis = Eigen::Vector3d(0, 0, -1);
  lamp.cone_degrees = 25.0;
  lamp.inner_degrees = 20.0;
  lamp.power = Eigen::Vector3d::Constant(4.0);
  const auto directional = [](const Eigen::Vector3d& direction, double power) {
    lights::Light light;
    light.direction = direction.normalized();
    light.power = Eigen::Vector3d::Constant(power);
    return light;
  };
  lights::LightSet room;
  room.lights = {directional({0.0, 0.0, 1.0}, 3.0),     // the lamp, straight above the probe
                 directional({0.05, 0.0, 1.0}, 1.0),    // 2.9 degrees off: the lamp's too
                 directional({0.3, 0.0, 1.0}, 0.5),     // 16.7 degrees off: the room's
                 directional({-1.0, 0.0, 0.2}, 0.25)};  // a window
  lights::Light virtual_light = directional({0.0, 0.0, 1.0}, 2.0);
  virtual_light.real = false;  // a virtual light is not in the probe
  room.lights.push_back(virtual_light);
  Eigen::Vector3d removed;
  const lights::LightSet kept = without_lamp_in_probe(room, lamp, Eigen::Vector3d::Zero(), removed);
  ASSERT_EQ(kept.lights.size(), 3u);
  EXPECT_EQ(removed, Eigen::Vector3d::Constant(4.0));
  EXPECT_DOUBLE_EQ(lamp_irradiance_at(lamp, Eigen::Vector3d::Zero()), 4.0);  // 4 W/sr at 1 m, on the axis
  // A probe 1 m to the side, 45 degrees off the lamp's axis: outside the 25-degree cone.
  const lights::LightSet all = without_lamp_in_probe(room, lamp, Eigen::Vector3d(1, 0, 0), removed);
  EXPECT_EQ(all.lights.size(), room.lights.size());
  EXPECT_EQ(removed, Eigen::Vector3d::Zero());
  EXPECT_DOUBLE_EQ(lamp_irradiance_at(lamp, Eigen::Vector3d(1, 0, 0)), 0.0);
}

}  // namespace
}  // namespace relight::app
