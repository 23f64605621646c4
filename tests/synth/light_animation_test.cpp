// Real light that changes in a synthetic sequence: the per-frame scene, probe stream and true lights.
#include "relight/synth/light_animation.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>

#include "relight/core/atomic_file.h"
#include "relight/core/error.h"
#include "relight/core/image_io.h"
#include "relight/synth/probe.h"
#include "relight/truth/sequence_writer.h"
#include "temp_dir.h"

namespace relight::synth {
namespace {

TEST(LightAnimation, SwitchesTheKeyLightAtTheEventFrame) {
  const Scene scene = default_indoor_scene();
  LightAnimationOptions on{.kind = LightAnimation::SwitchOn, .event_frame = 3};
  EXPECT_EQ(scene_at_frame(scene, on, 2, 6).lights.size(), scene.lights.size() - 1);
  EXPECT_EQ(scene_at_frame(scene, on, 3, 6).lights.size(), scene.lights.size());
  // The light left on is the other one.
  EXPECT_EQ(scene_at_frame(scene, on, 0, 6).lights[0].position, scene.lights[1].position);
  LightAnimationOptions off{.kind = LightAnimation::SwitchOff};  // default: half way
  EXPECT_EQ(scene_at_frame(scene, off, 2, 6).lights.size(), scene.lights.size());
  EXPECT_EQ(scene_at_frame(scene, off, 3, 6).lights.size(), scene.lights.size() - 1);
}

TEST(LightAnimation, OrbitKeepsHeightAndDistanceAndTurnsByTheAngle) {
  const Scene scene = default_indoor_scene();
  const LightAnimationOptions orbit{.kind = LightAnimation::Orbit, .orbit_degrees = 60};
  const PointLight& first = scene.lights[0];
  const Scene turned = scene_at_frame(scene, orbit, 4, 5);
  const PointLight& last = turned.lights[0];
  EXPECT_DOUBLE_EQ(last.position.z(), first.position.z());
  const Eigen::Vector2d a = first.position.head<2>() - scene.look_at.head<2>();
  const Eigen::Vector2d b = last.position.head<2>() - scene.look_at.head<2>();
  EXPECT_NEAR(a.norm(), b.norm(), 1e-12);
  const double turn = std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b)) * 180.0 / std::numbers::pi;
  EXPECT_NEAR(turn, 60.0, 1e-9);  // counter-clockwise seen from above
  EXPECT_EQ(scene_at_frame(scene, orbit, 0, 5).lights[0].position, first.position);
}

TEST(LightAnimation, DimScalesTheIntensityLinearly) {
  const Scene scene = default_indoor_scene();
  const LightAnimationOptions dim{.kind = LightAnimation::Dim, .dim_to = 0.2};
  EXPECT_DOUBLE_EQ(scene_at_frame(scene, dim, 0, 5).lights[0].intensity, scene.lights[0].intensity);
  EXPECT_NEAR(scene_at_frame(scene, dim, 2, 5).lights[0].intensity, 0.6 * scene.lights[0].intensity, 1e-12);
  EXPECT_NEAR(scene_at_frame(scene, dim, 4, 5).lights[0].intensity, 0.2 * scene.lights[0].intensity, 1e-12);
  EXPECT_EQ(scene_at_frame(scene, dim, 4, 5).lights[1].intensity, scene.lights[1].intensity);
}

TEST(LightAnimation, BadOptionsAreErrors) {
  const Scene scene = default_indoor_scene();
  EXPECT_THROW((void)scene_at_frame(scene, {.kind = LightAnimation::Dim, .light = 5}, 0, 4), Error);
  EXPECT_THROW((void)scene_at_frame(scene, {.kind = LightAnimation::Dim, .dim_to = 2}, 0, 4), Error);
  EXPECT_THROW((void)scene_at_frame(scene, {.kind = LightAnimation::SwitchOn, .event_frame = 4}, 0, 4), Error);
}

TEST(LightAnimation, SequenceWritesTheProbeStreamAndTheTrueLightsOfEveryFrame) {
  test::TempDir dir;
  SynthOptions options;
  options.frames = 3;
  options.width = 32;
  options.height = 24;
  options.trajectory = Trajectory::Static;
  options.noise = NoiseModel::None;
  options.light_animation = {.kind = LightAnimation::SwitchOn, .event_frame = 1};
  truth::write_sequence(options, dir.path());
  std::ifstream list(dir.path() / "probe.txt");
  std::string line;
  std::vector<std::string> files;
  while (std::getline(list, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    double timestamp = 0;
    std::string file;
    fields >> timestamp >> file;
    EXPECT_NEAR(timestamp, frame_timestamp(static_cast<int>(files.size())), 1e-6);
    files.push_back(file);
  }
  ASSERT_EQ(files.size(), 3u);
  // The key light is off in frame 0's probe and on in frame 1's: the probe gains its power.
  const auto power = [&](const std::string& file) {
    double sum = 0;
    const RadianceImage probe = read_radiance(dir.path() / file);
    for (const Float3& p : probe.pixels()) sum += p.x;
    return sum;
  };
  EXPECT_GT(power(files[1]), 1.2 * power(files[0]));
  EXPECT_NEAR(power(files[1]), power(files[2]), 1e-6 * power(files[1]));
  const auto lights_of = [&](const std::string& file) {
    const std::string stem = std::filesystem::path(file).stem().string();
    return nlohmann::json::parse(read_text_file(dir.path() / "gt" / "lights" / (stem + ".json")))["lights"];
  };
  EXPECT_EQ(lights_of(files[0]).size(), 1u);
  EXPECT_EQ(lights_of(files[1]).size(), 2u);
  const auto scene = nlohmann::json::parse(read_text_file(dir.path() / "scene.json"));
  EXPECT_EQ(scene["light_animation"]["kind"], "switch-on");
  EXPECT_EQ(scene["light_animation"]["event_frame"], 1);
  // What render-reference reads back to light each frame as the sequence did.
  const SequenceLightAnimation read =
      light_animation_of_scene_json(read_text_file(dir.path() / "scene.json"), "scene.json");
  EXPECT_EQ(read.animation.kind, LightAnimation::SwitchOn);
  EXPECT_EQ(read.animation.event_frame, 1);
  EXPECT_EQ(read.frames, 3);
  EXPECT_EQ(light_animation_of_scene_json(R"({"frames": 4})", "s").animation.kind, LightAnimation::None);
  EXPECT_THROW((void)light_animation_of_scene_json(R"({"light_animation": {"kind": "blink"}})", "s"), Error);
  EXPECT_THROW((void)light_animation_of_scene_json("{", "s"), Error);
}

}  // namespace
}  // namespace relight::synth
