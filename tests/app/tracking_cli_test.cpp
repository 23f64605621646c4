// `relight replay` with camera tracking (--pose): the trajectory every run writes, odometry and
// marker+odometry on a synthetic orbit measured against its exact poses, and one-line errors for
// pose sources a sequence cannot give.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "cli.h"
#include "relight/core/atomic_file.h"
#include "temp_dir.h"

namespace relight {
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
  TempDir dir;
  const auto out = dir.path() / "auto";
  const auto result = relight("replay --quiet --no-object --no-frames --out " + out.string());  // embedded TUM sample
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(tracking_of(out)["source"], "sequence");  // the sample has groundtruth.txt
  EXPECT_EQ(pose_lines(out / "camera_trajectory.txt"), 4);
}

// Measured: odometry ATE 0.08 cm, RPE 0.01 deg; marker+odometry ATE 0.4 cm (the marker's own
// error sets its world frame), its per-frame marker correction at most 0.23 cm.
TEST(ReplayTracking, OdometryAndMarkerOdometryFollowTheSyntheticOrbit) {
  TempDir dir;
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
  TempDir dir;
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

}  // namespace
}  // namespace relight
