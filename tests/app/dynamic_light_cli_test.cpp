// `relight replay` with real light that changes: the probe stream of a synthetic sequence whose
// key light switches at frame k is extracted and smoothed every frame, and the virtual object's
// shadow on the real table follows it (Knecht 2010 §6: DIR follows dynamic real light).
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <numbers>

#include "cli.h"
#include "relight/core/atomic_file.h"
#include "relight/core/image_io.h"
#include "temp_dir.h"

namespace relight::app {
namespace {

using cli_test::expect_one_line_error;
using cli_test::relight;

const std::filesystem::path kData = RELIGHT_TEST_DATA;
constexpr int kFrames = 6;
constexpr int kSwitchFrame = 3;

// `relight replay` of `sequence` with the shipped pebble into `out`, L_rv/L_r written per frame.
test::CommandResult replay_pebble(const std::filesystem::path& sequence, const std::filesystem::path& out,
                                  const std::string& extra = "") {
  return relight("replay --quiet " + sequence.string() + " --object " +
                 (kData / "models" / "glossy_pebble.gltf").string() + " --buffers --no-video --out " + out.string() +
                 " " + extra);
}

// frames/<frame, 6 digits><suffix>, as the frame writer names its files.
std::filesystem::path frame_file(const std::filesystem::path& frames, int frame, const char* suffix) {
  char stem[16];
  std::snprintf(stem, sizeof stem, "%06d", frame);
  return frames / (std::string(stem) + suffix);
}

// The light the virtual object takes from real surfaces: sum of L_r - L_rv over pixels it does
// not cover (its shadow; its bounce light on them counts against it).
struct FrameLight {
  double shadow = 0.0;      // sum of L_r - L_rv where the object does not cover
  double real_light = 0.0;  // mean of L_r over uncovered pixels
  double camera = 0.0;      // mean linear camera value over the same pixels
};

double srgb_to_linear(std::uint8_t v) {
  const double c = v / 255.0;
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

FrameLight frame_light(const std::filesystem::path& frames, int frame) {
  const RadianceImage lrv = read_radiance(frame_file(frames, frame, "_L_rv.exr"));
  const RadianceImage lr = read_radiance(frame_file(frames, frame, "_L_r.exr"));
  const ColorImage coverage = read_color(frame_file(frames, frame, "_virtual_coverage.png"));
  const ColorImage camera = read_color(frame_file(frames, frame, "_color.png"));
  FrameLight light;
  double count = 0.0;
  for (int row = 0; row < lrv.height(); ++row) {
    for (int col = 0; col < lrv.width(); ++col) {
      if (coverage(row, col).r != 0) continue;
      const Float3 a = lr(row, col), b = lrv(row, col);
      const double delta = (a.x - b.x) + (a.y - b.y) + (a.z - b.z);
      light.shadow += delta;
      light.real_light += a.x + a.y + a.z;
      const Rgb8 c = camera(row, col);
      light.camera += srgb_to_linear(c.r) + srgb_to_linear(c.g) + srgb_to_linear(c.b);
      count += 1.0;
    }
  }
  light.real_light /= count;
  light.camera /= count;
  return light;
}

// Relative error of DIR's differential light L_rv - L_r of `frame` against the path tracer's
// (render-reference at half the resolution: `reference` holds L_rv, beside it .Lr.exr), summed
// over the pixels the virtual object covers in none of the 2x2 replay pixels they average.
double delta_error_against_reference(const std::filesystem::path& frames, int frame,
                                     const std::filesystem::path& reference) {
  const RadianceImage lrv = read_radiance(frame_file(frames, frame, "_L_rv.exr"));
  const RadianceImage lr = read_radiance(frame_file(frames, frame, "_L_r.exr"));
  const ColorImage coverage = read_color(frame_file(frames, frame, "_virtual_coverage.png"));
  const RadianceImage truth_rv = read_radiance(reference);
  auto truth_r_path = reference;
  const RadianceImage truth_r = read_radiance(truth_r_path.replace_extension(".Lr.exr"));
  EXPECT_EQ(truth_rv.width() * 2, lrv.width());
  double error = 0.0, total = 0.0;
  for (int row = 0; row < truth_rv.height(); ++row) {
    for (int col = 0; col < truth_rv.width(); ++col) {
      Eigen::Vector3d ours = Eigen::Vector3d::Zero();
      bool covered = false;
      for (int dy = 0; dy < 2; ++dy) {
        for (int dx = 0; dx < 2; ++dx) {
          const int r = 2 * row + dy, c = 2 * col + dx;
          covered = covered || coverage(r, c).r != 0;
          ours += 0.25 * (Eigen::Vector3d(lrv(r, c).x, lrv(r, c).y, lrv(r, c).z) -
                          Eigen::Vector3d(lr(r, c).x, lr(r, c).y, lr(r, c).z));
        }
      }
      if (covered) continue;
      const Float3 a = truth_rv(row, col), b = truth_r(row, col);
      const Eigen::Vector3d truth(a.x - b.x, a.y - b.y, a.z - b.z);
      error += (ours - truth).cwiseAbs().sum();
      total += truth.cwiseAbs().sum();
    }
  }
  return total > 0.0 ? error / total : 1.0;
}

struct DynamicLightRun {
  std::vector<FrameLight> frames;
  nlohmann::json report;
};

// Replays a synthetic sequence (static camera, the pebble on the table) whose key light changes.
DynamicLightRun run_with_light(const std::string& animation, const test::TempDir& dir) {
  const auto& sequence = cli_test::synthetic_sequence(
      "--frames " + std::to_string(kFrames) + " --size 320x240 --trajectory static --light-animation " + animation +
      " --light-event-frame " + std::to_string(kSwitchFrame));
  const auto out = dir.path() / animation;
  const auto result = replay_pebble(sequence, out);
  EXPECT_EQ(result.exit_code, 0) << result.err;
  DynamicLightRun run;
  if (result.exit_code != 0) return run;
  for (int frame = 0; frame < kFrames; ++frame) run.frames.push_back(frame_light(out / "frames", frame));
  run.report = nlohmann::json::parse(read_text_file(out / "report.json"));
  return run;
}

// The switch at frame k changes the camera image by some ratio; the rendered real light L_r, lit
// by the lights extracted from the frame's probe, changes by the same ratio by frame k + 2 (within
// 25 %: L_r holds 8 sampled lights, the camera the exact sky and lamps), and so does the object's
// shadow on the table. Before the switch the lights do not change; the shadow moves by less
// than 10 % (what the indirect light's temporal accumulation and the materials' clustering still
// settle over the first frames).
void expect_light_follows_the_switch(const DynamicLightRun& run) {
  ASSERT_EQ(run.frames.size(), static_cast<std::size_t>(kFrames));
  const FrameLight& before = run.frames[kSwitchFrame - 1];
  for (int frame = 1; frame < kSwitchFrame; ++frame) {
    EXPECT_NEAR(run.frames[static_cast<std::size_t>(frame)].shadow, run.frames[0].shadow, 0.1 * run.frames[0].shadow)
        << "frame " << frame << ": a static probe and camera keep the shadow";
  }
  for (int frame = kSwitchFrame + 2; frame < kFrames; ++frame) {
    const FrameLight& after = run.frames[static_cast<std::size_t>(frame)];
    const double camera_ratio = after.camera / before.camera;
    const double render_ratio = after.real_light / before.real_light;
    EXPECT_GT(std::abs(std::log(camera_ratio)), std::log(1.3)) << "the switch changes the camera image";
    EXPECT_NEAR(std::log(render_ratio), std::log(camera_ratio), std::log(1.25))
        << "frame " << frame << ": L_r changed by " << render_ratio << ", the camera by " << camera_ratio;
    EXPECT_GT(std::abs(after.shadow - before.shadow), 0.1 * before.shadow)
        << "frame " << frame << ": the object's shadow follows the light";
  }
}

TEST(DynamicLightCli, ALightSwitchedOnReachesTheRenderWithinTwoFrames) {
  test::TempDir dir;
  const DynamicLightRun run = run_with_light("switch-on", dir);
  expect_light_follows_the_switch(run);
  const auto& probe = run.report["probe"];
  EXPECT_EQ(probe["timing"], "timestamped");
  EXPECT_EQ(probe["probes_used"], kFrames);
  EXPECT_EQ(probe["frames_kept_last_probe"], 0);
  bool extraction = false, smoothing = false;
  for (const auto& stage : run.report["stages"]) {
    extraction = extraction || stage["stage"] == "light_extraction";
    smoothing = smoothing || stage["stage"] == "light_smoothing";
  }
  EXPECT_TRUE(extraction && smoothing) << "the graph extracts and smooths the lights every frame";
}

TEST(DynamicLightCli, ALightSwitchedOffLeavesTheRenderWithinTwoFrames) {
  test::TempDir dir;
  const DynamicLightRun run = run_with_light("switch-off", dir);
  expect_light_follows_the_switch(run);
}

// A real lamp (--real-spot) beside the pebble: it lights the real table in both worlds (L_r
// grows) and the pebble casts its shadow onto the table (L_r - L_rv grows), with the first VPLs
// traced or taken from its two reflective shadow maps (real layer, virtual layer).
TEST(DynamicLightCli, ARealSpotLightsTheTableAndThePebbleCastsItsShadow) {
  test::TempDir dir;
  const auto& sequence = cli_test::synthetic_sequence("--frames 2 --size 320x240 --trajectory static --no-gt");
  const auto run = [&](const std::string& name, const std::string& extra) {
    const auto out = dir.path() / name;
    const auto result = replay_pebble(sequence, out, extra);
    EXPECT_EQ(result.exit_code, 0) << result.err;
    return result.exit_code == 0 ? frame_light(out / "frames", 1) : FrameLight{};
  };
  const FrameLight without = run("without", "");
  for (const std::string source : {"rays", "rsm"}) {
    SCOPED_TRACE(source);
    const FrameLight with =
        run("with_" + source, "--real-spot 0.95,-0.2,1.35,0.35,-0.2,0.75,30,3 --vpl-source " + source);
    EXPECT_GT(with.real_light, 1.05 * without.real_light);
    EXPECT_GT(with.shadow, 1.2 * without.shadow) << "the pebble's shadow of the lamp";
  }
  expect_one_line_error(relight("replay --quiet " + sequence.string() + " --object " +
                                (kData / "models" / "glossy_pebble.gltf").string() +
                                " --real-spot 0,0,1,0,0,1,30,1 --out " + (dir.path() / "bad").string()),
                        1);
}

// Sensor noise on a static probe (static camera and light): the temporal smoothing of the lights
// makes the rendered light flicker less than half as much as the lights extracted frame by frame.
TEST(DynamicLightCli, LightSmoothingHalvesTheFlickerOfANoisyProbe) {
  test::TempDir dir;
  const auto& sequence =
      cli_test::synthetic_sequence("--frames 8 --size 320x240 --trajectory static --noise none --probe-noise 0.3");
  const auto flicker = [&](const std::string& name, const std::string& extra) {
    const auto out = dir.path() / name;
    const auto result = replay_pebble(sequence, out, extra);
    EXPECT_EQ(result.exit_code, 0) << result.err;
    // Mean absolute change between consecutive frames, after the first two (warm-up), of what
    // the composite adds to the camera image: the object and its light and shadow, L_rv - L_r.
    const auto delta = [&](int frame) {
      RadianceImage difference = read_radiance(frame_file(out / "frames", frame, "_L_rv.exr"));
      const RadianceImage real = read_radiance(frame_file(out / "frames", frame, "_L_r.exr"));
      for (std::size_t i = 0; i < difference.size(); ++i) {
        Float3& d = difference.pixels()[i];
        d = {d.x - real.pixels()[i].x, d.y - real.pixels()[i].y, d.z - real.pixels()[i].z};
      }
      return difference;
    };
    double sum = 0.0;
    int count = 0;
    RadianceImage previous = delta(2);
    for (int frame = 3; frame < 8; ++frame) {
      const RadianceImage current = delta(frame);
      for (std::size_t i = 0; i < current.size(); ++i) {
        const Float3 p = previous.pixels()[i], c = current.pixels()[i];
        sum += std::abs(c.x - p.x) + std::abs(c.y - p.y) + std::abs(c.z - p.z);
        ++count;
      }
      previous = current;
    }
    return sum / count;
  };
  const double smoothed = flicker("smoothed", "");
  const double raw = flicker("raw", "--no-light-smoothing");
  EXPECT_GT(raw, 0.0) << "the noisy probe moves the extracted lights";
  EXPECT_LT(smoothed, 0.5 * raw) << "smoothed " << smoothed << ", raw " << raw;
}

// Without a probe (--lights estimate) the lights come from the frames: the graph estimates the
// environment every frame, extracts and smooths lights from it, and the pebble casts a shadow
// on the table at least half as deep as the probe's lights give it. (It comes out twice as deep:
// the estimate puts the lamp into one light, the probe's 8 lights spread it and add the walls'
// bounce light, which the synthetic camera image does not have; the path-tracer comparison that
// says which is closer is still to come, so only the lower bound is asserted.)
TEST(DynamicLightCli, LightsEstimatedFromTheFramesCastThePebblesShadowWithoutAProbe) {
  test::TempDir dir;
  const auto& sequence = cli_test::synthetic_sequence("--frames 3 --size 320x240 --trajectory static --no-gt");
  const auto with_probe = dir.path() / "probe";
  const auto estimated = dir.path() / "estimated";
  ASSERT_EQ(replay_pebble(sequence, with_probe).exit_code, 0);
  const auto result = replay_pebble(sequence, estimated, "--lights estimate");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto report = nlohmann::json::parse(read_text_file(estimated / "report.json"));
  ASSERT_TRUE(report.contains("light_estimate")) << report.dump();
  EXPECT_NE(report["light_estimate"]["evidence"], "none");
  EXPECT_GT(report["light_estimate"]["voxels"].get<int>(), 1000);
  bool estimation = false, extraction = false;
  for (const auto& stage : report["stages"]) {
    estimation = estimation || stage["stage"] == "light_estimation";
    extraction = extraction || stage["stage"] == "light_extraction";
  }
  EXPECT_TRUE(estimation && extraction);
  const FrameLight truth = frame_light(with_probe / "frames", 2);
  const FrameLight estimate = frame_light(estimated / "frames", 2);
  EXPECT_GT(estimate.shadow, 0.5 * truth.shadow);
  std::cout << "pebble shadow: estimated lights " << estimate.shadow << ", the probe's " << truth.shadow << "\n";
}

// --environment vpls: the probe's lights (64 by default) reach the scene as emitter VPLs
// shadowed by their ISMs instead of shadow-mapped directional lights, and report.json says which
// mode ran. With the same 8 lights the pebble's shadow on the table and the real light keep
// their size; the ISMs' coarser real-real occlusion lets somewhat more light through. Measured
// (320x240, frame 1, sums over the uncovered pixels): shadow 188.9 shadow-mapped, 224.7 as
// VPLs, 320.2 as 64 VPLs (269.6 as 64 shadow-mapped lights); mean L_r 0.395, 0.434, 0.478.
TEST(DynamicLightCli, EnvironmentAsVplsCastsThePebblesShadowLikeDirectionalLights) {
  test::TempDir dir;
  const auto& sequence = cli_test::synthetic_sequence("--frames 2 --size 320x240 --trajectory static --no-gt");
  const auto directional = dir.path() / "directional", vpls = dir.path() / "vpls", vpls8 = dir.path() / "vpls8";
  ASSERT_EQ(replay_pebble(sequence, directional).exit_code, 0);
  const auto result = replay_pebble(sequence, vpls, "--environment vpls");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  ASSERT_EQ(replay_pebble(sequence, vpls8, "--environment vpls --probe-lights 8").exit_code, 0);
  const auto report = nlohmann::json::parse(read_text_file(vpls / "report.json"));
  EXPECT_EQ(report["environment"]["mode"], "vpls");
  EXPECT_EQ(report["environment"]["extracted_lights"], 64);
  const auto baseline = nlohmann::json::parse(read_text_file(directional / "report.json"));
  EXPECT_EQ(baseline["environment"]["mode"], "directional");
  EXPECT_EQ(baseline["environment"]["extracted_lights"], 8);
  const FrameLight shadow_maps = frame_light(directional / "frames", 1);
  const FrameLight emitters = frame_light(vpls8 / "frames", 1);
  const FrameLight dense = frame_light(vpls / "frames", 1);
  std::cout << "pebble shadow: 8 shadow-mapped lights " << shadow_maps.shadow << ", 8 emitter VPLs " << emitters.shadow
            << ", 64 emitter VPLs " << dense.shadow << "; mean L_r " << shadow_maps.real_light << ", "
            << emitters.real_light << ", " << dense.real_light << "\n";
  ASSERT_GT(shadow_maps.shadow, 0.0);
  EXPECT_NEAR(emitters.shadow, shadow_maps.shadow, 0.35 * shadow_maps.shadow);
  EXPECT_NEAR(emitters.real_light, shadow_maps.real_light, 0.15 * shadow_maps.real_light);
  EXPECT_GT(dense.shadow, 0.8 * shadow_maps.shadow);
  expect_one_line_error(
      relight("replay --quiet " + sequence.string() + " --environment sky --out " + (dir.path() / "bad").string()), 2);
}

TEST(DynamicLightCli, ProbeInputErrorsAreOneLine) {
  test::TempDir dir;
  const auto& sequence = cli_test::synthetic_sequence("--frames 2 --size 320x240 --trajectory static --no-gt");
  const std::string replay = "replay --quiet " + sequence.string() + " --object " +
                             (kData / "models" / "glossy_pebble.gltf").string() + " --no-video --out " +
                             (dir.path() / "out").string();
  expect_one_line_error(relight(replay + " --probe " + (dir.path() / "missing.hdr").string()), 1);
  { std::ofstream(dir.path() / "probe.txt") << "2.0 a.hdr\n1.0 b.hdr\n"; }
  expect_one_line_error(relight(replay + " --probe " + (dir.path() / "probe.txt").string()), 1);
  expect_one_line_error(relight(replay + " --probe-rotation 1,2"), 2);  // a usage error
  expect_one_line_error(relight(replay + " --probe-exposure 0"), 1);
}

// A hand-held lamp tracked through a tag of its own (dissertation §5.2.12): relight re-poses the
// real spot every frame from the tag and the camera's pose. The lamp turns by 40 degrees from
// beside the pebble (frame 0) onto it (the last frame): the pebble's shadow grows with it, and
// is larger than without the lamp; the tracked light sits where the sequence's true lamp is.
TEST(DynamicLightCli, ATrackedLampIsWhereItsTagSaysAndThePebblesShadowFollowsIt) {
  test::TempDir dir;
  constexpr int kLampFrames = 4;
  const auto& sequence = cli_test::synthetic_sequence("--frames " + std::to_string(kLampFrames) +
                                                      " --size 320x240 --trajectory static --light-animation "
                                                      "pocket-lamp --light-orbit-degrees 40");
  const auto scene = nlohmann::json::parse(read_text_file(sequence / "scene.json"));
  ASSERT_TRUE(scene.contains("pocket_lamp"));
  // The room's lights are the scene's; the lamp comes from its tag alone.
  const std::string room = "--pose sequence --lights " + (sequence / "scene.json").string();
  const auto run = [&](const std::string& name, const std::string& extra) {
    const auto out = dir.path() / name;
    const auto result = replay_pebble(sequence, out, room + " " + extra);
    EXPECT_EQ(result.exit_code, 0) << result.err;
    std::vector<FrameLight> frames;
    for (int frame = 0; result.exit_code == 0 && frame < kLampFrames; ++frame)
      frames.push_back(frame_light(out / "frames", frame));
    return frames;
  };
  const auto with = run("lamp", scene["pocket_lamp"]["replay_options"].get<std::string>());
  const auto without = run("room", "");
  ASSERT_EQ(with.size(), static_cast<std::size_t>(kLampFrames));
  ASSERT_EQ(without.size(), static_cast<std::size_t>(kLampFrames));
  EXPECT_GT(with.back().shadow, 1.2 * with.front().shadow) << "the lamp turned onto the pebble";
  // Against the path tracer's differential light of the last frame (the true lamp and room): the
  // tracked lamp brings DIR's shadow closer to it than the room's lights alone.
  const auto reference = dir.path() / "reference.exr";
  const auto traced =
      relight("render-reference --quiet --sequence " + sequence.string() + " --frame " +
              std::to_string(kLampFrames - 1) + " --object " + (kData / "models" / "glossy_pebble.gltf").string() +
              " --spp 64 --downsample 2 --out " + reference.string());
  ASSERT_EQ(traced.exit_code, 0) << traced.err;
  const double error_with = delta_error_against_reference(dir.path() / "lamp" / "frames", kLampFrames - 1, reference);
  const double error_without =
      delta_error_against_reference(dir.path() / "room" / "frames", kLampFrames - 1, reference);
  std::cerr << "DeltaL relative error against the path tracer: " << error_with << " with the lamp, " << error_without
            << " without\n";
  EXPECT_LT(error_with, 0.85 * error_without);

  const auto report = nlohmann::json::parse(read_text_file(dir.path() / "lamp" / "report.json"));
  const auto& lamp = report["tracked_lamp"];
  EXPECT_EQ(lamp["frames_seen"], kLampFrames) << lamp.dump();
  // The last frame's true lamp: the spot of its gt/lights file.
  std::vector<std::filesystem::path> truths;
  for (const auto& entry : std::filesystem::directory_iterator(sequence / "gt" / "lights"))
    truths.push_back(entry.path());
  ASSERT_EQ(truths.size(), static_cast<std::size_t>(kLampFrames));
  const auto truth =
      nlohmann::json::parse(read_text_file(*std::max_element(truths.begin(), truths.end())))["lights"].back();
  ASSERT_EQ(truth["type"], "spot");
  const auto vec = [](const nlohmann::json& v) { return Eigen::Vector3d(v[0], v[1], v[2]); };
  EXPECT_LT((vec(lamp["last_position"]) - vec(truth["position"])).norm(), 0.02) << lamp.dump();
  EXPECT_GT(vec(lamp["last_axis"]).dot(vec(truth["axis"])), std::cos(3.0 * std::numbers::pi / 180.0)) << lamp.dump();
}

TEST(DynamicLightCli, TrackedLampErrorsAreOneLineAndAnUnseenTagIsAWarning) {
  test::TempDir dir;
  const auto& sequence = cli_test::synthetic_sequence("--frames 2 --size 320x240 --trajectory static --no-gt");
  const std::string replay = "replay --quiet " + sequence.string() + " --object " +
                             (kData / "models" / "glossy_pebble.gltf").string() + " --no-video --out " +
                             (dir.path() / "out").string();
  expect_one_line_error(relight(replay + " --real-spot-tag 1,0.16,25"), 1);
  expect_one_line_error(relight(replay + " --real-spot-tag 1.5,0.16,25,3"), 1);
  expect_one_line_error(relight(replay + " --real-spot-tag 1,0,25,3"), 1);
  expect_one_line_error(relight(replay + " --real-spot-tag 1,0.16,95,3"), 1);
  expect_one_line_error(relight(replay + " --real-spot-tag 1,0.16,25,3 --real-spot-tag-offset 0,0,0,0,0,0"), 1);
  expect_one_line_error(relight(replay + " --real-spot-tag-offset 0,0.1,0"), 1);
  // This sequence has no lamp: the run goes on with the room's lights and says so once.
  const auto result = relight(replay + " --real-spot-tag 1,0.16,25,3");
  EXPECT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.err.find("was in no frame"), std::string::npos) << result.err;
  const auto report = nlohmann::json::parse(read_text_file(dir.path() / "out" / "report.json"));
  EXPECT_EQ(report["tracked_lamp"]["frames_seen"], 0);
  EXPECT_EQ(report["tracked_lamp"]["frames_before_first_sighting"], 2);
}

}  // namespace
}  // namespace relight::app
