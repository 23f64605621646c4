// relight devices / live / record / replay FILE.oni as users run them, on relight's own OpenNI2
// device (relight://synthetic): outputs and the .oni round trip (depth bit-identical to synth's
// ground truth, timestamps and frame count kept). Ctrl-C, an unplugged device and cut recordings
// are rows of the robustness matrix (tests/robustness/device_robustness_test.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "relight/capture/depth_millimetres.h"
#include "relight/capture/openni_source.h"
#include "relight/capture/tum_sequence.h"
#include "relight/core/atomic_file.h"
#include "relight/synth/raycast.h"
#include "relight/synth/scene.h"
#include "relight/synth/sequence.h"
#include "relight/synth/trajectory.h"
#include "run_command.h"
#include "temp_dir.h"

namespace relight::app {
namespace {

const std::string kRelight = RELIGHT_BIN;
// 320x240 keeps the synthetic renderer fast (~45 ms a frame) and the tests short.
const std::string kDevice = "'relight://synthetic?size=320x240'";

test::CommandResult relight(const std::string& arguments) { return test::run_command(kRelight + " " + arguments); }

void expect_one_line_error(const test::CommandResult& result, const std::string& part) {
  EXPECT_EQ(result.exit_code, 1) << result.err;
  EXPECT_EQ(result.err.rfind("relight: error: ", 0), 0u) << result.err;
  EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
  EXPECT_NE(result.err.find(part), std::string::npos) << result.err;
}

nlohmann::json read_report(const std::filesystem::path& folder) {
  return nlohmann::json::parse(read_text_file(folder / "report.json"));
}

std::vector<std::uint16_t> to_mm(const DepthMap& depth) {
  std::vector<std::uint16_t> mm(depth.size());
  for (std::size_t i = 0; i < mm.size(); ++i) mm[i] = capture::depth_to_millimetres(depth.data()[i]);
  return mm;
}

// Synthetic device frame k (orbit, 320x240): synth's exact depth in millimetres.
std::vector<std::uint16_t> ground_truth_mm(std::int64_t k) {
  static const synth::Scene scene = synth::default_indoor_scene();
  static const auto poses = synth::make_trajectory(synth::Trajectory::Orbit, 540, 0, scene);
  synth::SynthOptions options;
  options.width = 320;
  options.height = 240;
  const auto rendered = synth::render_frame(scene, synth::synth_intrinsics(options), poses[static_cast<std::size_t>(k)]);
  return to_mm(rendered.depth);
}

std::uint64_t device_timestamp_us(std::int64_t k) { return static_cast<std::uint64_t>(std::llround(1e6 * (1.0 + k / 30.0))); }

TEST(OpenNiCli, DevicesListsTheSyntheticDevice) {
  const auto result = relight("devices");
  EXPECT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.out.find("relight://synthetic\trelight\t"), std::string::npos) << result.out;
}

TEST(OpenNiCli, LiveRunsTheReplayGraphForNFrames) {
  test::TempDir dir;
  // The command as CI runs it: the default 640x480 device.
  const auto result = relight("live --quiet --device relight://synthetic --frames 2 --out " + dir.path().string());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_TRUE(result.err.empty()) << result.err;
  const auto report = read_report(dir.path());
  EXPECT_EQ(report["frames"], 2);
  EXPECT_EQ(report["stopped_by"], "end");
  EXPECT_NE(report["source"].get<std::string>().find("relight://synthetic"), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "graph.dot"));
  std::size_t pngs = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir.path() / "frames")) pngs += entry.path().extension() == ".png";
  EXPECT_GE(pngs, 2u * 4u);  // colour, depth, smoothed depth, normals per frame
}

// live tracks the device's camera (no poses come from a device: auto is odometry) and writes its
// trajectory; rendering without --lights names the device, not the embedded sample.
TEST(OpenNiCli, LiveTracksTheCameraAndLightsAVirtualDeviceFromTheSceneItServes) {
  test::TempDir dir;
  const auto result =
      relight("live --quiet --no-frames --markers none --device \"relight://synthetic?trajectory=orbit&size=320x240\" "
              "--frames 3 --out " + dir.path().string());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto report = read_report(dir.path());
  EXPECT_EQ(report["tracking"]["source"], "odometry");  // no layout: markerless
  EXPECT_EQ(report["tracking"]["frames_tracked"], 3) << report["tracking"].dump();
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "camera_trajectory.txt"));
  // The virtual device serves its scene (probe, tag layout): live lights and tracks it as replay
  // would the same sequence; a device without a scene has its lights estimated (below).
  const std::string model = std::string(RELIGHT_TEST_DATA) + "/models/glossy_pebble.gltf";
  const auto rendered = dir.path() / "render";
  const auto lit = relight("live --quiet --no-video --device \"relight://synthetic?size=320x240\" --frames 1 --vpls 8 --object " +
                           model + " --out " + rendered.string());
  ASSERT_EQ(lit.exit_code, 0) << lit.err;
  EXPECT_TRUE(std::filesystem::exists(rendered / "frames" / "000000_composite.png"));
  const auto lit_report = read_report(rendered);
  EXPECT_EQ(lit_report["tracking"]["source"], "marker+odometry");  // --markers auto: the device's tag
  EXPECT_EQ(lit_report["latency_ms"]["frames"], 1);
  EXPECT_GT(lit_report["latency_ms"]["median_ms"].get<double>(), 0.0);
  ASSERT_TRUE(lit_report.contains("device_memory")) << lit_report.dump();  // live reports it as replay does
  EXPECT_GT(lit_report["device_memory"]["allocations"].get<int>(), 0);
  // A device without a probe: its lights are estimated from its frames, and the run says so.
  const std::string tum = "relight://tum/" + std::string(RELIGHT_TEST_DATA) + "/tum_fr1_rpy";
  const auto estimated = relight("live --device " + tum + " --frames 1 --vpls 8 --no-video --object " + model +
                                 " --place 0,0,0.8 --out " + (dir.path() / "tum").string());
  ASSERT_EQ(estimated.exit_code, 0) << estimated.err;
  EXPECT_NE(estimated.err.find("the device " + tum + " serves no light probe: the real lights are estimated"),
            std::string::npos)
      << estimated.err;
  const auto estimated_report = read_report(dir.path() / "tum");
  ASSERT_TRUE(estimated_report.contains("light_estimate")) << estimated_report.dump();
  EXPECT_EQ(estimated_report["light_estimate"]["chosen"], "the device " + tum + " serves no light probe");
}

TEST(OpenNiCli, UnknownDeviceIsAClearError) {
  test::TempDir dir;
  expect_one_line_error(relight("live --device relight://nowhere --out " + dir.path().string()), "relight://nowhere");
}

TEST(OpenNiCli, RecordReplayRoundTripKeepsDepthTimestampsAndFrameCount) {
  test::TempDir dir;
  const auto oni = dir.path() / "take.oni";
  const auto recorded = relight("record --device " + kDevice + " --frames 4 --out " + oni.string());
  ASSERT_EQ(recorded.exit_code, 0) << recorded.err;
  ASSERT_TRUE(std::filesystem::exists(oni));
  const capture::OniRecordingSummary summary = capture::inspect_oni(oni);
  // Every frame read after the recorder started (all but possibly the first) is in the file.
  EXPECT_GE(summary.depth_frames, 3);
  EXPECT_EQ(summary.depth_frames, summary.color_frames);

  // Played back, frame i is synthetic frame k0 + i, bit for bit, with the device's spacing.
  capture::OpenNiOptions options;
  options.uri = oni.string();
  capture::OpenNiSource playback(options);
  EXPECT_TRUE(playback.is_file());
  EXPECT_EQ(playback.size_hint(), summary.depth_frames);
  std::vector<RgbdFrame> frames;
  std::vector<std::uint64_t> timestamps;
  while (auto frame = playback.next()) {
    frames.push_back(std::move(*frame));
    timestamps.push_back(playback.last_timestamp_us());
  }
  ASSERT_EQ(static_cast<std::int64_t>(frames.size()), summary.depth_frames);
  std::int64_t k0 = -1;
  const auto first = to_mm(frames[0].depth);
  for (std::int64_t k = 0; k < 12 && k0 < 0; ++k) {
    if (ground_truth_mm(k) == first) k0 = k;
  }
  ASSERT_GE(k0, 0) << "the first recorded frame is none of the device's first 12";
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const auto k = k0 + static_cast<std::int64_t>(i);
    EXPECT_EQ(to_mm(frames[i].depth), ground_truth_mm(k)) << "frame " << i;
    EXPECT_EQ(timestamps[i] - timestamps[0], device_timestamp_us(k) - device_timestamp_us(k0)) << "frame " << i;
  }

  // relight replay FILE.oni runs the graph over all of it.
  const auto out = dir.path() / "replay";
  const auto replayed = relight("replay --quiet --no-frames --cpu " + oni.string() + " --out " + out.string());
  ASSERT_EQ(replayed.exit_code, 0) << replayed.err;
  EXPECT_EQ(read_report(out)["frames"], summary.depth_frames);
}

TEST(OpenNiCli, RecordToAFolderWritesATumSequence) {
  test::TempDir dir;
  const auto folder = dir.path() / "take";
  const auto result = relight("record --quiet --device " + kDevice + " --frames 3 --out " + folder.string());
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const capture::TumSequence sequence = capture::TumSequence::open(folder);
  ASSERT_EQ(sequence.size(), 3u);
  for (std::size_t i = 0; i < sequence.size(); ++i) {
    const auto k = std::llround((sequence.frame(i).depth_timestamp - 1.0) * 30.0);
    EXPECT_EQ(to_mm(sequence.load(i).depth), ground_truth_mm(k)) << i;
  }
}

}  // namespace
}  // namespace relight::app
