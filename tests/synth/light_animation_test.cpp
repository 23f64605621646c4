// Real light that changes in a synthetic sequence: the per-frame scene, probe stream and true lights.
#include "relight/synth/light_animation.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <filesystem>
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

// A static 32x24 sequence without noise, `frames` long, with `animation`.
void write_tiny_sequence(const LightAnimationOptions& animation, int frames, const std::filesystem::path& out) {
  SynthOptions options;
  options.frames = frames;
  options.width = 32;
  options.height = 24;
  options.trajectory = Trajectory::Static;
  options.noise = NoiseModel::None;
  options.light_animation = animation;
  truth::write_sequence(options, out);
}

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
  // A lower orbit: the same turn and horizontal distance at the height asked for.
  LightAnimationOptions low = orbit;
  low.orbit_height = 1.2;
  const Scene lowered_scene = scene_at_frame(scene, low, 4, 5);
  const PointLight& lowered = lowered_scene.lights[0];
  EXPECT_DOUBLE_EQ(lowered.position.z(), 1.2);
  EXPECT_NEAR((lowered.position.head<2>() - last.position.head<2>()).norm(), 0.0, 1e-12);
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
  EXPECT_THROW((void)scene_at_frame(scene, {.kind = LightAnimation::Orbit, .orbit_height = -1.0}, 0, 3), Error);
  EXPECT_THROW((void)scene_at_frame(scene, {.kind = LightAnimation::Dim, .light = 5}, 0, 4), Error);
  EXPECT_THROW((void)scene_at_frame(scene, {.kind = LightAnimation::Dim, .dim_to = 2}, 0, 4), Error);
  EXPECT_THROW((void)scene_at_frame(scene, {.kind = LightAnimation::SwitchOn, .event_frame = 4}, 0, 4), Error);
}

TEST(LightAnimation, SequenceWritesTheProbeStreamAndTheTrueLightsOfEveryFrame) {
  test::TempDir dir;
  write_tiny_sequence({.kind = LightAnimation::SwitchOn, .event_frame = 1}, 3, dir.path());
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

TEST(PocketLamp, ItsLightIsFixedToItsTagAtEveryTurn) {
  const Scene scene = default_indoor_scene();
  const PocketLamp straight = pocket_lamp(scene, 0.0);
  // At no turn it aims at the table's tag, from above the table.
  const Eigen::Vector3d to_tag = (scene.tags.front().centre - straight.light.position).normalized();
  EXPECT_NEAR(straight.light.axis.dot(to_tag), 1.0, 1e-12);
  EXPECT_GT(straight.light.position.z(), scene.look_at.z() + 0.1);
  EXPECT_TRUE(straight.light.spot());
  EXPECT_EQ(straight.tag.id, 1);
  for (const double degrees : {-30.0, 10.0, 45.0}) {
    const PocketLamp lamp = pocket_lamp(scene, degrees);
    Eigen::Matrix3d tag_to_world;
    tag_to_world << lamp.tag.x_axis, lamp.tag.y_axis, lamp.tag.z_axis();
    EXPECT_NEAR((tag_to_world.transpose() * tag_to_world - Eigen::Matrix3d::Identity()).norm(), 0.0, 1e-12);
    // The calibration is the same at every turn, and it places the light.
    EXPECT_EQ(lamp.position_in_tag, straight.position_in_tag);
    EXPECT_NEAR((lamp.axis_in_tag - straight.axis_in_tag).norm(), 0.0, 1e-12);
    EXPECT_NEAR((lamp.tag.centre + tag_to_world * lamp.position_in_tag - lamp.light.position).norm(), 0.0, 1e-12);
    EXPECT_NEAR((tag_to_world * lamp.axis_in_tag - lamp.light.axis).norm(), 0.0, 1e-12);
    // Turned about the vertical: the axis keeps its slope and turns by the angle.
    EXPECT_NEAR(lamp.light.axis.z(), straight.light.axis.z(), 1e-12);
    const Eigen::Vector2d a = straight.light.axis.head<2>(), b = lamp.light.axis.head<2>();
    EXPECT_NEAR(std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b)) * 180.0 / std::numbers::pi, degrees, 1e-9);
    // The card carries the tag, its face outwards (where the tag's z points in).
    EXPECT_NEAR(lamp.card.normal.dot(lamp.tag.z_axis()), -1.0, 1e-12);
    EXPECT_GT(lamp.card.half_u, 0.5 * lamp.tag.size * 10.0 / 8.0);
  }
}

TEST(PocketLamp, ItLightsTheTableInsideItsConeOnly) {
  const Scene scene = default_indoor_scene();
  const LightAnimationOptions lamp{.kind = LightAnimation::PocketLamp, .orbit_degrees = 40};
  const Scene first = scene_at_frame(scene, lamp, 0, 5);
  ASSERT_EQ(first.lights.size(), scene.lights.size() + 1);
  ASSERT_EQ(first.objects.size(), scene.objects.size() + 1);
  ASSERT_EQ(first.tags.size(), scene.tags.size() + 1);
  EXPECT_EQ(first.tags.back().object, static_cast<int>(scene.objects.size()));
  const PointLight& light = first.lights.back();
  EXPECT_NEAR(light.axis.dot(pocket_lamp(scene, -20.0).light.axis), 1.0, 1e-12);  // frame 0: -orbit / 2
  // Where its axis meets the table (z = 0.75) the lamp adds its full E = I cos / d^2; well
  // outside the cone it adds nothing.
  const double t = (scene.look_at.z() - light.position.z()) / light.axis.z();
  const Eigen::Vector3d centre = light.position + t * light.axis, up = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d added = unoccluded_irradiance(first, centre, up) - unoccluded_irradiance(scene, centre, up);
  EXPECT_NEAR(added.x(), light.colour.x() * light.intensity * -light.axis.z() / (t * t), 1e-9);
  const Eigen::Vector3d aside = centre + 0.8 * (centre - light.position).cross(up).normalized();
  EXPECT_NEAR((unoccluded_irradiance(first, aside, up) - unoccluded_irradiance(scene, aside, up)).norm(), 0.0, 1e-12);
  EXPECT_DOUBLE_EQ(light.falloff(light.axis), 1.0);
  const Eigen::Vector3d outside = Eigen::AngleAxisd(0.5, light.axis.unitOrthogonal()) * light.axis;  // 28.6 deg
  EXPECT_DOUBLE_EQ(light.falloff(outside), 0.0);
  // Half way between the cosines of the inner and the outer angle the smoothstep is one half.
  const double degree = std::numbers::pi / 180.0;
  const double half_way = std::acos(0.5 * (std::cos(20.0 * degree) + std::cos(25.0 * degree)));
  const Eigen::Vector3d between = Eigen::AngleAxisd(half_way, light.axis.unitOrthogonal()) * light.axis;
  EXPECT_NEAR(light.falloff(between), 0.5, 1e-9);
}

TEST(PocketLamp, SceneJsonGivesTheReplayOptionsAndEveryFrameItsSpot) {
  test::TempDir dir;
  write_tiny_sequence({.kind = LightAnimation::PocketLamp}, 2, dir.path());
  const auto scene = nlohmann::json::parse(read_text_file(dir.path() / "scene.json"));
  ASSERT_TRUE(scene.contains("pocket_lamp")) << scene.dump(2);
  EXPECT_EQ(scene["pocket_lamp"]["tag_id"], 1);
  const std::string replay = scene["pocket_lamp"]["replay_options"];
  EXPECT_EQ(replay.rfind("--real-spot-tag 1,0.16,25,6,1,0.9,0.75 --real-spot-tag-offset 0,0.12,0,", 0), 0u) << replay;
  // Its tag is not one of the world's: the marker layout (scene.json's "tag") stays the table's.
  EXPECT_EQ(scene["tag"]["id"], 0);
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(dir.path() / "gt" / "lights"))
    files.push_back(entry.path());
  ASSERT_EQ(files.size(), 2u);
  const auto lights = nlohmann::json::parse(read_text_file(*std::max_element(files.begin(), files.end())))["lights"];
  ASSERT_EQ(lights.size(), 3u);
  EXPECT_EQ(lights[2]["type"], "spot");
  EXPECT_EQ(lights[2]["cone_degrees"], 25.0);
}

}  // namespace
}  // namespace relight::synth
