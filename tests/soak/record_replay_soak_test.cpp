// Record -> replay round trip of N live frames from relight's synthetic OpenNI2 device, into a .oni
// file and into a TUM RGB-D folder: every frame bit-exact (depth equal to synth's ground truth,
// colour equal wherever the device's loop repeats a frame), timestamps kept, nothing lost that
// reached the recorder, and `relight replay` runs over all of it.
// N = RELIGHT_SOAK_FRAMES (default 1000; CI runs 100). The device serves a 30-frame loop from
// memory after its first pass, so it runs at its 30 fps and the soak takes N / 30 s per recording.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>

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

namespace relight {
namespace {

constexpr int kLoop = 30;
const std::string kDevice = "'relight://synthetic?size=320x240&loop=30'";

int soak_frames() {
  const char* text = std::getenv("RELIGHT_SOAK_FRAMES");
  return text != nullptr && std::atoi(text) > 0 ? std::atoi(text) : 1000;
}

test::CommandResult relight(const std::string& arguments) {
  return test::run_command(std::string(RELIGHT_BIN) + " " + arguments);
}

std::vector<std::uint16_t> to_mm(const DepthMap& depth) {
  std::vector<std::uint16_t> mm(depth.size());
  for (std::size_t i = 0; i < mm.size(); ++i) mm[i] = capture::depth_to_millimetres(depth.data()[i]);
  return mm;
}

// The device's frame k (orbit of kLoop frames, 320x240): synth's exact depth in millimetres.
const std::vector<std::uint16_t>& ground_truth_mm(std::int64_t k) {
  static const std::vector<std::vector<std::uint16_t>> loop = [] {
    const synth::Scene scene = synth::default_indoor_scene();
    const auto poses = synth::make_trajectory(synth::Trajectory::Orbit, kLoop, 0, scene);
    synth::SynthOptions options;
    options.width = 320;
    options.height = 240;
    std::vector<std::vector<std::uint16_t>> frames;
    frames.reserve(poses.size());
    for (const auto& pose : poses)
      frames.push_back(to_mm(synth::render_frame(scene, synth::synth_intrinsics(options), pose).depth));
    return frames;
  }();
  return loop[static_cast<std::size_t>(k % kLoop)];
}

std::int64_t dropped_by_the_reader(const std::string& err) {
  std::smatch match;
  if (!std::regex_search(err, match, std::regex(R"(, (\d+) dropped by the reader)"))) return -1;
  return std::stoll(match[1]);
}

// Checks frames in recording order, `seconds[i]` their timestamps (device clock, or relative to
// the first): depth equal to the ground truth of their device frame, colour equal to any earlier
// frame of the same loop position, device frames increasing. Returns the frames the device sent
// in that span that are not there.
std::int64_t check_frames(const std::vector<RgbdFrame>& frames, const std::vector<double>& seconds) {
  std::int64_t k0 = -1;  // the device frame of the first recorded frame
  for (std::int64_t k = 0; k < kLoop && k0 < 0; ++k) {
    if (ground_truth_mm(k) == to_mm(frames.front().depth)) k0 = k;
  }
  EXPECT_GE(k0, 0) << "the first recorded frame is none of the device's loop";
  if (k0 < 0) return -1;
  std::map<std::int64_t, const ColorImage*> colour_of_loop_index;
  std::int64_t previous = -1, missing = 0;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const double k_real = static_cast<double>(k0) + (seconds[i] - seconds[0]) * 30.0;
    const auto k = std::llround(k_real);
    EXPECT_NEAR(k_real, static_cast<double>(k), 1e-3) << "frame " << i << ": timestamp off the device clock";
    EXPECT_GT(k, previous) << "frame " << i;
    if (previous >= 0) missing += k - previous - 1;
    previous = k;
    EXPECT_EQ(to_mm(frames[i].depth), ground_truth_mm(k)) << "frame " << i << " (device frame " << k << ")";
    const auto [seen, first] = colour_of_loop_index.try_emplace(k % kLoop, &frames[i].color);
    if (!first) {
      EXPECT_TRUE(std::equal(seen->second->data(), seen->second->data() + seen->second->size(), frames[i].color.data()))
          << "frame " << i;
    }
  }
  return missing;
}

/// `relight record` of `frames` frames from the device into `out` (.oni or folder), with its summary.
test::CommandResult record(int frames, const std::filesystem::path& out) {
  return relight("record --device " + kDevice + " --frames " + std::to_string(frames) + " --out " + out.string());
}

void expect_replay_runs_over(const std::filesystem::path& input, std::size_t frames, const std::filesystem::path& out) {
  const auto replayed = relight("replay --quiet --no-frames --cpu " + input.string() + " --out " + out.string());
  ASSERT_EQ(replayed.exit_code, 0) << replayed.err;
  EXPECT_EQ(nlohmann::json::parse(read_text_file(out / "report.json"))["frames"].get<std::size_t>(), frames);
}

TEST(RecordReplaySoak, OniRecordingKeepsEveryFrameBitExact) {
  const int n = soak_frames();
  test::TempDir dir;
  const auto oni = dir.path() / "take.oni";
  const auto recorded = record(n, oni);
  ASSERT_EQ(recorded.exit_code, 0) << recorded.err;
  capture::OpenNiOptions options;
  options.uri = oni.string();
  capture::OpenNiSource playback(options);
  std::vector<RgbdFrame> frames;
  std::vector<double> seconds;
  while (auto frame = playback.next()) {
    frames.push_back(std::move(*frame));
    seconds.push_back(static_cast<double>(playback.last_timestamp_us()) * 1e-6);
  }
  // The recorder attaches to the streams themselves: it holds every frame the device sent from the
  // moment it started, those the reader got and those it dropped (and one more when a frame came
  // in as the recorder started).
  const std::int64_t dropped = dropped_by_the_reader(recorded.err);
  ASSERT_GE(dropped, 0) << recorded.err;
  const auto sent = static_cast<std::size_t>(n + dropped);
  ASSERT_GE(frames.size(), sent) << recorded.err;
  ASSERT_LE(frames.size(), sent + 1) << recorded.err;
  EXPECT_EQ(check_frames(frames, seconds), 0);
  expect_replay_runs_over(oni, frames.size(), dir.path() / "replay");
}

TEST(RecordReplaySoak, TumFolderKeepsEveryFrameTheReaderGotBitExact) {
  const int n = soak_frames();
  test::TempDir dir;
  const auto folder = dir.path() / "take";
  const auto recorded = record(n, folder);
  ASSERT_EQ(recorded.exit_code, 0) << recorded.err;
  const capture::TumSequence sequence = capture::TumSequence::open(folder);
  ASSERT_EQ(sequence.size(), static_cast<std::size_t>(n));
  std::vector<RgbdFrame> frames;
  std::vector<double> seconds;
  for (std::size_t i = 0; i < sequence.size(); ++i) {
    frames.push_back(sequence.load(i));
    seconds.push_back(sequence.frame(i).depth_timestamp);
    // Timestamps kept: the device clock itself (frame k at 1 s + k / 30 s).
    const double k = (seconds.back() - 1.0) * 30.0;
    EXPECT_NEAR(k, std::round(k), 1e-3) << "frame " << i;
  }
  // A reader that falls behind the device loses frames (OpenNI2 keeps the newest); record says
  // how many, and exactly those are missing between the frames it wrote.
  EXPECT_EQ(check_frames(frames, seconds), dropped_by_the_reader(recorded.err)) << recorded.err;
  expect_replay_runs_over(folder, frames.size(), dir.path() / "replay");
}

}  // namespace
}  // namespace relight
