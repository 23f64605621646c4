// Robustness matrix, a replay in progress: Ctrl-C in the middle of a TUM folder (with and without
// rendering, and with a probe stream and the odometry) finalises the outputs and exits 130 with
// one line; an AprilTag layout none of whose tags is in view runs to the end with one warning and
// no marker pose; a disk that fills up is one line naming the file, exit 1, and what was written
// before it intact.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "inputs.h"
#include "outcome_checks.h"
#include "tmpfs_mount.h"

namespace relight::robustness {
namespace {

nlohmann::json read_report(const std::filesystem::path& folder) {
  return nlohmann::json::parse(read_text_file(folder / "report.json"));
}

void expect_interrupted_replay(const RunOutcome& run, const std::filesystem::path& out, int frames_listed) {
  ASSERT_TRUE(run.interrupted) << describe(run);
  expect_no_crash_or_hang(run);
  EXPECT_EQ(run.exit_code, 130) << describe(run);
  EXPECT_EQ(count_lines(run.err), 1u) << run.err;
  EXPECT_EQ(run.err.rfind("relight: warning: replay interrupted after ", 0), 0u) << run.err;
  const auto unfinished = unfinished_outputs(out);
  EXPECT_TRUE(unfinished.empty()) << unfinished.front();
  const auto report = read_report(out);
  EXPECT_EQ(report["stopped_by"], "interrupt");
  EXPECT_GE(report["frames"].get<int>(), 2);
  EXPECT_LT(report["frames"].get<int>(), frames_listed);
  EXPECT_NE(run.err.find(" " + std::to_string(report["frames"].get<int>()) + " of "), std::string::npos) << run.err;
}

TEST(ReplayRunRobustness, CtrlCDuringReplayOfATumFolder) {
  test::TempDir dir;
  const auto sequence = copy_of_sample(dir.path() / "seq");
  loop_sequence(sequence, 400);
  const auto out = dir.path() / "out";
  BoundedRun replay;
  replay.arguments = {"replay", "--quiet", "--cpu", sequence.string(), "--out", out.string()};
  replay.interrupt_when = [&] { return std::filesystem::exists(out / "frames" / "000001_color.png"); };
  expect_interrupted_replay(run_relight(replay), out, 400);
}

// With virtual content composite.mp4 is being written when the signal comes: it must be complete.
TEST(ReplayRunRobustness, CtrlCDuringReplayWithRendering) {
  test::TempDir dir;
  const auto sequence = copy_of_synthetic(dir.path() / "seq");
  loop_sequence(sequence, 200);
  const auto out = dir.path() / "out";
  BoundedRun replay;
  replay.arguments = {"replay", "--quiet", sequence.string(), "--object", (kData / "models" / "glossy_pebble.gltf").string(),
                      "--vpls", "8", "--out", out.string()};
  replay.interrupt_when = [&] { return std::filesystem::exists(out / "frames" / "000001_composite_mapped.png"); };
  const auto run = run_relight(replay);
  expect_interrupted_replay(run, out, 200);
  EXPECT_TRUE(std::filesystem::exists(out / "composite.mp4"));
}

// The stages the tracking and dynamic-light work added - the odometry, the probe stream and the
// per-frame light extraction - are running when the signal comes.
TEST(ReplayRunRobustness, CtrlCDuringReplayWithAProbeStreamAndOdometry) {
  test::TempDir dir;
  const auto sequence = dir.path() / "seq";
  std::filesystem::copy(animated_light_sequence(), sequence, std::filesystem::copy_options::recursive);
  loop_sequence(sequence, 200);
  const auto out = dir.path() / "out";
  BoundedRun replay;
  replay.arguments = {"replay",
                      "--quiet",
                      sequence.string(),
                      "--pose",
                      "odometry",
                      "--object",
                      (kData / "models" / "glossy_pebble.gltf").string(),
                      "--vpls",
                      "8",
                      "--out",
                      out.string()};
  replay.interrupt_when = [&] { return std::filesystem::exists(out / "frames" / "000001_composite_mapped.png"); };
  const auto run = run_relight(replay);
  expect_interrupted_replay(run, out, 200);
  EXPECT_TRUE(std::filesystem::exists(out / "composite.mp4"));
  const auto report = read_report(out);
  EXPECT_EQ(report["tracking"]["source"], "odometry") << report["tracking"].dump();
  EXPECT_GE(report["probe"]["probes_used"].get<int>(), report["frames"].get<int>()) << report["probe"].dump();
  EXPECT_EQ(report["probe"]["frames_kept_last_probe"], 0) << report["probe"].dump();
  const auto trajectory = read_text_file(out / "camera_trajectory.txt");
  EXPECT_EQ(trajectory.back(), '\n') << "camera_trajectory.txt ends in the middle of a line";
}

TEST(ReplayRunRobustness, TagLayoutWithNoTagInView) {
  test::TempDir dir;
  const auto layout = dir.path() / "layout.json";
  write_file_atomically(layout, std::string_view(R"({"family": "tag36h11", "tags": [{"id": 7, "size": 0.16,
    "corners_world": [[0, 0, 0], [0.16, 0, 0], [0.16, 0.16, 0], [0, 0.16, 0]]}]})"));
  const auto out = dir.path() / "out";
  const auto run = run_relight({"replay", "--quiet", "--cpu", (kData / "tum_fr1_rpy").string(), "--markers",
                                layout.string(), "--out", out.string()});
  expect_clean_success(run, out);
  EXPECT_EQ(count_lines(run.err), 1u) << run.err;
  EXPECT_EQ(run.err.rfind("relight: warning: ", 0), 0u) << run.err;
  EXPECT_NE(run.err.find(layout.string()), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("4 frames"), std::string::npos) << run.err;
  const auto report = read_report(out);
  EXPECT_EQ(report["frames"], 4);
  EXPECT_EQ(report["marker_pose"]["frames_with_marker_pose"], 0);
  const std::string trajectory = read_text_file(out / "marker_trajectory.txt");
  EXPECT_EQ(count_lines(trajectory), 2u) << "the header and no pose:\n" << trajectory;
}

TEST(ReplayRunRobustness, MalformedTagLayout) {
  test::TempDir dir;
  const auto layout = dir.path() / "layout.json";
  write_file_atomically(layout, std::string_view(R"({"family": "tag36h11", "tags": [{"id": 7}]})"));
  const auto out = dir.path() / "out";
  expect_clean_error(run_relight({"replay", "--quiet", "--cpu", (kData / "tum_fr1_rpy").string(), "--markers",
                                  layout.string(), "--out", out.string()}),
                     1, layout.string(), out);
}

TEST(ReplayRunRobustness, DiskFullDuringReplay) {
  test::TempDir dir;
  const auto out = dir.path() / "out";
  const TmpfsMount small_disk(out, "1m");
  if (!small_disk.mounted()) GTEST_SKIP() << small_disk.why_not();
  const auto run = run_relight({"replay", "--quiet", "--cpu", (kData / "tum_fr1_rpy").string(), "--out", out.string()});
  // one line naming the file that did not fit, exit 1, no temporary or half-written file left
  expect_clean_error(run, 1, (out / "frames").string(), out);
  EXPECT_NE(run.err.find("No space left on device"), std::string::npos) << run.err;
  // the first frame's images, written before the disk filled, are there and read back
  EXPECT_TRUE(std::filesystem::exists(out / "frames" / "000000_color.png"));
  EXPECT_TRUE(std::filesystem::exists(out / "frames" / "000000_depth.png"));
}

}  // namespace
}  // namespace relight::robustness
