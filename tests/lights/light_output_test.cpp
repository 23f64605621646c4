#include "relight/lights/light_output.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "relight/core/error.h"

namespace relight::lights {
namespace {

TEST(LightOutput, JsonRoundTripKeepsEveryLight) {
  // Every vector spelled out: `{}` would value-initialise an Eigen vector to garbage (Eigen's
  // default constructor leaves it uninitialised), not to the member's default.
  LightSet set;
  set.lights.push_back(
      {LightKind::Directional, Eigen::Vector3d(0, 0.6, 0.8), Eigen::Vector3d::Zero(), {1.5, 1.2, 0.9}, true});
  set.lights.push_back({LightKind::Point, Eigen::Vector3d::UnitZ(), {0.5, -0.2, 2.0}, {3, 3, 3}, false});
  const LightSet back = lights_from_json(lights_to_json(set), "test");
  ASSERT_EQ(back.lights.size(), 2u);
  EXPECT_EQ(back.lights[0].kind, LightKind::Directional);
  EXPECT_TRUE(back.lights[0].direction.isApprox(set.lights[0].direction, 1e-12));
  EXPECT_TRUE(back.lights[0].power.isApprox(set.lights[0].power, 1e-12));
  EXPECT_EQ(back.lights[1].kind, LightKind::Point);
  EXPECT_TRUE(back.lights[1].position.isApprox(set.lights[1].position, 1e-12));
  EXPECT_FALSE(back.lights[1].real);
}

// Found by lights_json_fuzzer: components near the largest double overflowed the plain norm, and
// the direction came out as zeros. Any finite non-zero vector is a direction; zero is an error.
TEST(LightOutput, HugeAndTinyDirectionsBecomeUnitVectorsAndZeroIsRefused) {
  const LightSet set = lights_from_json(
      R"({"lights": [{"type": "directional", "direction": [1e300, 1e300, 1e300], "power": [1, 1, 1]},
                     {"type": "spot", "position": [0, 0, 2], "axis": [0, 3e-7, -4e-7], "cone_degrees": 30,
                      "power": [1, 1, 1]}]})",
      "huge.json");
  ASSERT_EQ(set.lights.size(), 2u);
  EXPECT_TRUE(set.lights[0].direction.isApprox(Eigen::Vector3d::Ones().normalized(), 1e-12));
  EXPECT_TRUE(set.lights[1].axis.isApprox(Eigen::Vector3d(0, 0.6, -0.8), 1e-12));
  EXPECT_THROW((void)lights_from_json(R"({"lights": [{"type": "directional", "direction": [0, 0, 1e-12],
                                                      "power": [1, 1, 1]}]})",
                                      "zero.json"),
               Error);
}

TEST(LightOutput, SpotLightsKeepTheirConeAndFadeOutAtItsEdge) {
  const LightSet set = lights_from_json(R"({"lights": [{"type": "spot", "position": [0, 0, 2], "axis": [0, 0, -3],
                                                        "cone_degrees": 30, "power": [5, 5, 5]}]})",
                                        "lamp.json");
  ASSERT_EQ(set.lights.size(), 1u);
  const Light& spot = set.lights[0];
  EXPECT_EQ(spot.kind, LightKind::Spot);
  EXPECT_TRUE(spot.axis.isApprox(-Eigen::Vector3d::UnitZ(), 1e-12));  // normalised
  EXPECT_DOUBLE_EQ(spot.inner_degrees, 24.0);                         // 0.8 of the cone by default
  const auto towards = [](double degrees) {
    const double a = degrees * std::numbers::pi / 180.0;
    return Eigen::Vector3d(std::sin(a), 0.0, -std::cos(a));
  };
  EXPECT_DOUBLE_EQ(spot_falloff(spot, towards(10)), 1.0);
  EXPECT_DOUBLE_EQ(spot_falloff(spot, towards(31)), 0.0);
  const double mid = spot_falloff(spot, towards(27));
  EXPECT_GT(mid, 0.0);
  EXPECT_LT(mid, 1.0);
  const LightSet back = lights_from_json(lights_to_json(set), "again");
  EXPECT_EQ(back.lights[0].kind, LightKind::Spot);
  EXPECT_DOUBLE_EQ(back.lights[0].cone_degrees, 30.0);
  EXPECT_DOUBLE_EQ(back.lights[0].inner_degrees, 24.0);
  EXPECT_TRUE(back.lights[0].position.isApprox(spot.position, 1e-12));
  for (const char* bad : {R"({"lights": [{"type": "spot", "position": [0, 0, 2], "power": [1, 1, 1]}]})",
                          R"({"lights": [{"type": "spot", "position": [0, 0, 2], "axis": [0, 0, 0], "cone_degrees": 30,
                                          "power": [1, 1, 1]}]})",
                          R"({"lights": [{"type": "spot", "position": [0, 0, 2], "axis": [0, 0, -1], "cone_degrees": 95,
                                          "power": [1, 1, 1]}]})",
                          R"({"lights": [{"type": "spot", "position": [0, 0, 2], "axis": [0, 0, -1], "cone_degrees": 20,
                                          "inner_degrees": 25, "power": [1, 1, 1]}]})"}) {
    EXPECT_THROW((void)lights_from_json(bad, "lamp.json"), Error) << bad;
  }
}

TEST(LightOutput, MalformedJsonNamesTheSourceAndTheLight) {
  const auto message = [](const std::string& text) {
    try {
      (void)lights_from_json(text, "lights.json");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("{ nope").find("lights.json: not valid JSON"), std::string::npos);
  EXPECT_NE(message("{}").find("\"lights\" array"), std::string::npos);
  EXPECT_NE(message(R"({"lights": [{"type": "area"}]})").find("light 0: unknown type 'area'"), std::string::npos);
  EXPECT_NE(message(R"({"lights": [{"type": "point", "position": [0, 0], "power": [1, 1, 1]}]})").find("'position'"),
            std::string::npos);
  EXPECT_NE(message(R"({"lights": [{"type": "directional", "direction": [0, 0, 1], "power": [1, -1, 1]}]})")
                .find("negative"),
            std::string::npos);
}

}  // namespace
}  // namespace relight::lights
