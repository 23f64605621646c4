// `relight replay` with camera tracking (--pose): the trajectory every run writes, odometry and
// marker+odometry on a synthetic orbit measured against its exact poses, and one-line errors for
// pose sources a sequence cannot give.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>
#include <sstream>
#include <nlohmann/json.hpp>

#include <Eigen/Core>

#include "cli.h"
#include "relight/capture/rgbd_odometry.h"
#include "relight/core/atomic_file.h"
#include "relight/core/image_io.h"
#include "temp_dir.h"

namespace relight::app {
namespace {

using cli_test::expect_one_line_error;
using cli_test::relight;

/// A synthetic orbit (20 degrees a second, Kinect v1 noise) with its tag and exact poses.
const std::filesystem::path& orbit_sequence() { return cli_test::synthetic_sequence("--frames 12 --trajectory orbit --no-gt"); }

int pose_lines(const std::filesystem::path& file) {
  const std::string text = read_text_file(file);
  int lines = 0;
  for (std::size_t start = 0; start < text.size();) {
    const std::size_t end = text.find('\n', start);
    if (text[start] != '#') ++lines;
    start = end == std::string::npos ? text.size() : end + 1;
  }
  return lines;
}

nlohmann::json tracking_of(const std::filesystem::path& out) {
  return nlohmann::json::parse(read_text_file(out / "report.json"))["tracking"];
}

TEST(ReplayTracking, EveryRunWritesTheCameraTrajectoryOfItsPoseSource) {
  test::TempDir dir;
  const auto out = dir.path() / "auto";
  const auto result = relight("replay --quiet --no-object --no-frames --out " + out.string());  // embedded TUM sample
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(tracking_of(out)["source"], "sequence");  // the sample has groundtruth.txt
  EXPECT_EQ(pose_lines(out / "camera_trajectory.txt"), 4);
}

// Measured: odometry ATE 0.08 cm, RPE 0.01 deg; marker+odometry ATE 0.4 cm (the marker's own
// error sets its world frame), its per-frame marker correction at most 0.23 cm.
TEST(ReplayTracking, OdometryAndMarkerOdometryFollowTheSyntheticOrbit) {
  test::TempDir dir;
  for (const std::string pose : {"odometry", "marker+odometry"}) {
    const auto out = dir.path() / pose;
    const auto result =
        relight("replay --quiet --no-frames " + orbit_sequence().string() + " --pose " + pose + " --out " + out.string());
    ASSERT_EQ(result.exit_code, 0) << result.err;
    const auto tracking = tracking_of(out);
    EXPECT_EQ(tracking["source"], pose);
    EXPECT_EQ(tracking["frames_tracked"], 12) << tracking.dump();
    EXPECT_EQ(pose_lines(out / "camera_trajectory.txt"), 12);
    EXPECT_LT(tracking["ate_cm"].get<double>(), pose == "odometry" ? 0.5 : 1.5) << tracking.dump();
    EXPECT_LT(tracking["rpe_deg"].get<double>(), 0.2) << tracking.dump();
    if (pose == "marker+odometry") {
      EXPECT_LE(tracking["max_marker_correction_cm"].get<double>(), 0.4 + 1e-9);
    }
  }
}

// `relight graph` shows the tracking stage for the pose options: with a tag layout and
// marker+odometry the marker pose runs before the tracking stage, which reads depth and colour.
TEST(ReplayTracking, GraphShowsTheTrackingStageOfThePoseOptions) {
  const auto plain = relight("graph");
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_NE(plain.out.find("camera_tracking\n"), std::string::npos) << plain.out;
  EXPECT_NE(plain.out.find("camera_trajectory\n"), std::string::npos) << plain.out;
  EXPECT_EQ(plain.out.find("marker_pose\n"), std::string::npos) << plain.out;
  const std::string layout = (orbit_sequence() / "scene.json").string();
  const auto marked = relight("graph --markers " + layout + " --pose marker+odometry");
  ASSERT_EQ(marked.exit_code, 0) << marked.err;
  const auto marker = marked.out.find("marker_pose\n"), tracking = marked.out.find("camera_tracking\n");
  ASSERT_NE(marker, std::string::npos) << marked.out;
  ASSERT_NE(tracking, std::string::npos) << marked.out;
  EXPECT_LT(marker, tracking) << marked.out;
  const auto dot = relight("graph --dot --markers " + layout + " --pose marker+odometry");
  EXPECT_NE(dot.out.find("\"buffer:marker_pose\" -> \"stage:camera_tracking\""), std::string::npos) << dot.out;
  EXPECT_NE(dot.out.find("\"buffer:depth\" -> \"stage:camera_tracking\""), std::string::npos) << dot.out;
  EXPECT_EQ(relight("graph --pose gps").exit_code, 2);
}

TEST(ReplayTracking, PoseSourcesTheSequenceCannotGiveAreOneLineErrors) {
  test::TempDir dir;
  // A copy of the orbit without its ground truth: --pose sequence has nothing to read.
  const auto copy = dir.path() / "no_truth";
  std::filesystem::copy(orbit_sequence(), copy, std::filesystem::copy_options::recursive);
  std::filesystem::remove(copy / "groundtruth.txt");
  const auto out = dir.path() / "out";
  expect_one_line_error(relight("replay --quiet --no-frames " + copy.string() + " --pose sequence --out " + out.string()), 1);
  expect_one_line_error(
      relight("replay --quiet --no-frames " + copy.string() + " --pose marker --markers none --out " + out.string()), 1);
  EXPECT_EQ(relight("replay --quiet " + copy.string() + " --pose gps --out " + out.string()).exit_code, 2);
  // auto on a sequence without poses: marker+odometry (its scene.json has a tag).
  const auto tracked = dir.path() / "tracked";
  ASSERT_EQ(relight("replay --quiet --no-frames " + copy.string() + " --out " + tracked.string()).exit_code, 0);
  EXPECT_EQ(tracking_of(tracked)["source"], "marker+odometry");
}

// The marker trajectory must have the shape of the sequence's own poses. A wrong tag size alone
// does not show (the marker pose's depth refinement rescales it), so here the sequence's poses
// are the wrong ones: a copy of the orbit whose groundtruth.txt has every camera twice as far
// from the first. The run stops with one line saying that layout and poses disagree.
TEST(ReplayTracking, ATagLayoutThatContradictsTheSequencePosesIsAnError) {
  test::TempDir dir;
  const auto copy = dir.path() / "stretched";
  std::filesystem::copy(orbit_sequence(), copy, std::filesystem::copy_options::recursive);
  std::istringstream truth(read_text_file(copy / "groundtruth.txt"));
  std::string stretched;
  std::optional<Eigen::Vector3d> first;
  for (std::string line; std::getline(truth, line);) {
    if (line.empty() || line[0] == '#') {
      stretched += line + "\n";
      continue;
    }
    std::istringstream fields(line);
    double t = 0, x = 0, y = 0, z = 0;
    std::string rotation, part;
    fields >> t >> x >> y >> z;
    while (fields >> part) rotation += " " + part;
    const Eigen::Vector3d position(x, y, z);
    if (!first) first = position;
    const Eigen::Vector3d moved = *first + 2.0 * (position - *first);
    char text[128];
    std::snprintf(text, sizeof text, "%.6f %.9f %.9f %.9f", t, moved.x(), moved.y(), moved.z());
    stretched += text + rotation + "\n";
  }
  write_file_atomically(copy / "groundtruth.txt", stretched);
  const auto result = relight("replay --quiet --no-frames " + copy.string() + " --out " + (dir.path() / "out").string());
  expect_one_line_error(result, 1);
  EXPECT_NE(result.err.find("contradicts the sequence's camera poses"), std::string::npos) << result.err;
  const std::size_t times = result.err.find(" times the size");
  ASSERT_NE(times, std::string::npos) << result.err;
  const double ratio = std::stod(result.err.substr(result.err.rfind(' ', times - 1) + 1));
  EXPECT_NEAR(ratio, 0.5, 0.1) << result.err;  // measured 0.53 (marker poses are good to ~1 cm)
  // The orbit as it is passes (the other tests replay it with its layout).
}

/// Camera positions of a TUM trajectory file by timestamp (rounded to 0.1 ms).
std::map<long long, Eigen::Vector3d> positions_by_time(const std::filesystem::path& file) {
  std::map<long long, Eigen::Vector3d> out;
  std::istringstream text(read_text_file(file));
  for (std::string line; std::getline(text, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    double t = 0, x = 0, y = 0, z = 0;
    fields >> t >> x >> y >> z;
    out[std::llround(t * 1e4)] = {x, y, z};
  }
  return out;
}

// marker+odometry over 300 frames (10 s, 200 degrees of orbit at 320x240 with Kinect v1 noise; the
// tag is seen in about 170 of them): the marker keeps the odometry in the layout's world, so the
// error to the true pose stays bounded and does not grow. Measured: at most 2.1 cm on any frame
// (1.5 cm over the first 100 frames, 2.0 over the last 100), ATE 0.95 cm.
TEST(ReplayTracking, MarkerOdometryDriftStaysBoundedOver300Frames) {
  test::TempDir dir;
  const auto sequence = cli_test::synthetic_sequence("--frames 300 --trajectory orbit --size 320x240 --no-gt");
  const auto out = dir.path() / "out";
  ASSERT_EQ(relight("replay --quiet --no-frames " + sequence.string() + " --pose marker+odometry --out " + out.string())
                .exit_code,
            0);
  const auto tracking = tracking_of(out);
  EXPECT_EQ(tracking["frames_tracked"], 300) << tracking.dump();
  EXPECT_LT(tracking["ate_cm"].get<double>(), 1.5) << tracking.dump();
  const auto tracked = positions_by_time(out / "camera_trajectory.txt");
  const auto truth = positions_by_time(sequence / "groundtruth.txt");
  std::vector<double> errors_cm;
  for (const auto& [time, position] : tracked) {
    const auto found = truth.find(time);
    ASSERT_NE(found, truth.end()) << time;
    errors_cm.push_back(100.0 * (position - found->second).norm());
  }
  ASSERT_EQ(errors_cm.size(), 300u);
  const double first = *std::max_element(errors_cm.begin(), errors_cm.begin() + 100);
  const double last = *std::max_element(errors_cm.end() - 100, errors_cm.end());
  std::printf("marker+odometry error to the true pose: max %.2f cm over frames 0-99, %.2f cm over 200-299\n", first,
              last);
  EXPECT_LT(*std::max_element(errors_cm.begin(), errors_cm.end()), 3.0);
  EXPECT_LT(last, first + 1.5);  // bounded: no growth worth the name over the run
}

/// Timestamps of a TUM trajectory file, in order.
std::vector<double> trajectory_timestamps(const std::filesystem::path& file) {
  std::vector<double> out;
  std::istringstream text(read_text_file(file));
  for (std::string line; std::getline(text, line);) {
    if (!line.empty() && line[0] != '#') out.push_back(std::stod(line));
  }
  return out;
}

/// The pebble's pixels: virtual coverage (written with --buffers) above one half.
std::vector<bool> virtual_pixels(const std::filesystem::path& frames, const std::string& frame) {
  const ColorImage coverage = read_color(frames / (frame + "_virtual_coverage.png"));
  std::vector<bool> mask(coverage.pixels().size());
  for (std::size_t i = 0; i < mask.size(); ++i) mask[i] = coverage.pixels()[i].r > 127;
  return mask;
}

/// Intersection over union of two pixel masks, and the size of their union.
std::pair<double, std::size_t> pebble_overlap(const std::vector<bool>& a, const std::vector<bool>& b) {
  std::size_t both = 0, either = 0;
  for (std::size_t p = 0; p < a.size(); ++p) {
    both += a[p] && b[p];
    either += a[p] || b[p];
  }
  return {either ? static_cast<double>(both) / static_cast<double>(either) : 0.0, either};
}

// Live mixed reality that holds still: `relight live` on the virtual device's orbit, tracked
// (marker+odometry from the layout the device serves, lit by the probe it serves), draws the
// pebble where a replay of the same frames with the true poses draws it. Measured at 640x480: IoU
// 0.966 to 0.969 per frame (the pebble ~2600 pixels; the marker pose that sets the world is good
// to about a centimetre; at 320x240 the same offset gave 0.945 to 0.966, depending on the frame
// the marker anchored the world at).
TEST(ReplayTracking, LiveOrbitDrawsThePebbleWhereAReplayWithTheTruePosesDoes) {
  test::TempDir dir;
  const std::string pebble = std::string(RELIGHT_TEST_DATA) + "/models/glossy_pebble.gltf";
  constexpr int kFps = 1;  // slow enough for the pipeline to take every frame, mostly
  const auto live = dir.path() / "live";
  const auto ran = relight("live --quiet --no-video --buffers --vpls 16 --device \"relight://synthetic?trajectory=orbit&fps=" +
                           std::to_string(kFps) + "\" --frames 4 --object " + pebble + " --out " + live.string());
  ASSERT_EQ(ran.exit_code, 0) << ran.err;
  EXPECT_EQ(tracking_of(live)["source"], "marker+odometry");
  // The device's frame k has timestamp 1 s + k / fps; the replay's frame k is the same view. The
  // replay holds every frame up to the last the live run took (a slower build, e.g. under the
  // sanitizers, drops more of them).
  const auto timestamps = trajectory_timestamps(live / "camera_trajectory.txt");
  ASSERT_EQ(timestamps.size(), 4u);
  std::vector<int> device_frames;
  device_frames.reserve(timestamps.size());
  for (const double timestamp : timestamps)
    device_frames.push_back(static_cast<int>(std::lround((timestamp - 1.0) * kFps)));
  const auto sequence = cli_test::synthetic_sequence("--frames " + std::to_string(device_frames.back() + 1) +
                                                     " --trajectory orbit --noise none --no-gt");
  const auto replay = dir.path() / "replay";
  ASSERT_EQ(relight("replay --quiet --no-video --buffers --vpls 16 --pose sequence " + sequence.string() +
                    " --object " + pebble + " --out " + replay.string())
                .exit_code,
            0);
  for (std::size_t i = 0; i < timestamps.size(); ++i) {
    const int k = device_frames[i];
    char live_name[32], replay_name[32];
    std::snprintf(live_name, sizeof live_name, "%06zu", i);
    std::snprintf(replay_name, sizeof replay_name, "%06d", k);
    const auto [iou, either] =
        pebble_overlap(virtual_pixels(live / "frames", live_name), virtual_pixels(replay / "frames", replay_name));
    ASSERT_GT(either, 400u) << "the pebble is in view in frame " << i;
    std::printf("live frame %zu (device frame %d): IoU %.3f of %zu pixels\n", i, k, iou, either);
    EXPECT_GE(iou, 0.95) << "frame " << i;
  }
}

// Anchor stability with markerless tracking: on the orbit and the hand-held path (Kinect v1
// noise), the pebble stood on the table at a pixel of the first frame (--place-at, so that the
// odometry's own world and the true one put it on the same spot) covers the pixels a replay with
// the true poses gives it, frame after frame.
TEST(ReplayTracking, OdometryKeepsThePebbleWhereTheTruePosesPutIt) {
  test::TempDir dir;
  const std::string pebble = std::string(RELIGHT_TEST_DATA) + "/models/glossy_pebble.gltf";
  for (const std::string trajectory : {"orbit", "handheld"}) {
    const auto sequence =
        cli_test::synthetic_sequence("--frames 8 --trajectory " + trajectory + " --size 320x240 --no-gt");
    const std::string common = "replay --quiet --no-video --buffers --vpls 8 " + sequence.string() + " --object " +
                               pebble + " --place-at 150,150 ";
    const auto tracked = dir.path() / (trajectory + "_odometry"), truth = dir.path() / (trajectory + "_truth");
    ASSERT_EQ(relight(common + "--pose odometry --out " + tracked.string()).exit_code, 0);
    ASSERT_EQ(relight(common + "--pose sequence --out " + truth.string()).exit_code, 0);
    // The report says what the odometry's model holds: a keyframe of 320x240 is 0.77 MB.
    const auto tracking = tracking_of(tracked);
    const int keyframes = tracking.value("keyframes", 0);
    EXPECT_GE(keyframes, 1) << tracking.dump();
    EXPECT_NEAR(tracking.value("keyframe_model_mb", 0.0), 0.77 * keyframes, 0.05 * keyframes) << tracking.dump();
    EXPECT_EQ(tracking.value("keyframe_model_budget_mb", 0.0), capture::RgbdOdometryOptions{}.model_budget_mb)
        << tracking.dump();
    double worst = 1.0;
    for (int frame = 0; frame < 8; ++frame) {
      char name[32];
      std::snprintf(name, sizeof name, "%06d", frame);
      const auto [iou, either] =
          pebble_overlap(virtual_pixels(tracked / "frames", name), virtual_pixels(truth / "frames", name));
      ASSERT_GT(either, 100u) << trajectory << " frame " << frame;
      worst = std::min(worst, iou);
    }
    std::printf("%s: worst pebble IoU odometry vs true poses %.3f\n", trajectory.c_str(), worst);
    EXPECT_GE(worst, 0.95) << trajectory;
  }
}

}  // namespace
}  // namespace relight::app
