// Robustness matrix, devices: no Vulkan driver at all (the CPU path, with one warning), relight's
// OpenNI2 device (relight://synthetic) unplugged mid-stream (and plugged back, with live waiting
// for it) or stopped with Ctrl-C during live and record, cut or empty .oni recordings, a disk that fills up while
// recording.
#include <gtest/gtest.h>

#include <chrono>
#include <nlohmann/json.hpp>
#include <optional>

#include "inputs.h"
#include "outcome_checks.h"
#include "relight/capture/openni_source.h"
#include "relight/capture/tum_sequence.h"
#include "tmpfs_mount.h"

namespace relight::robustness {
namespace {

// 320x240 keeps the synthetic device fast (~45 ms a frame).
const std::string kDevice = "relight://synthetic?size=320x240";

TEST(DeviceRobustness, NoVulkanDriverRendersOnTheCpuWithOneWarning) {
  test::TempDir dir;
  const auto out = dir.path() / "out";
  BoundedRun run;
  run.arguments = {"replay", "--quiet", synthetic_sequence().string(), "--object",
                   (kData / "models" / "glossy_pebble.gltf").string(), "--vpls", "8", "--out", out.string()};
  // Older loaders read VK_ICD_FILENAMES, newer ones VK_DRIVER_FILES: both point at nothing.
  const std::string nowhere = (dir.path() / "no_driver.json").string();
  run.environment = {{"VK_ICD_FILENAMES", nowhere}, {"VK_DRIVER_FILES", nowhere}};
  const auto outcome = run_relight(run);
  expect_clean_success(outcome, out);
  EXPECT_EQ(count_lines(outcome.err), 1u) << outcome.err;
  EXPECT_EQ(outcome.err.rfind("relight: warning: no usable Vulkan device, using the CPU path", 0), 0u) << outcome.err;
  EXPECT_TRUE(std::filesystem::exists(out / "frames" / "000001_composite_mapped.png"));
  EXPECT_TRUE(std::filesystem::exists(out / "composite.mp4"));
}

nlohmann::json read_report(const std::filesystem::path& folder) {
  return nlohmann::json::parse(read_text_file(folder / "report.json"));
}

// `relight ARGUMENTS --object <pebble> --vpls 8 --out OUT` with the Vulkan device reporting
// itself lost from frame `frame` on (the test hook of app/device_loss.h).
RunOutcome run_with_device_lost_at(std::vector<std::string> arguments, int frame, const std::filesystem::path& out) {
  BoundedRun run;
  run.arguments = std::move(arguments);
  for (const std::string& argument : {std::string("--object"), (kData / "models" / "glossy_pebble.gltf").string(),
                                      std::string("--vpls"), std::string("8"), std::string("--out"), out.string()}) {
    run.arguments.push_back(argument);
  }
  run.environment = {{"RELIGHT_TEST_DEVICE_LOST_AT_FRAME", std::to_string(frame)}};
  return run_relight(run);
}

// Lost from frame 1 on: frame 0's outputs finalised (its images, a one-frame video, the report),
// then one line naming the frame and --cpu, exit 1, no hang.
TEST(DeviceRobustness, GpuLostDuringReplay) {
  test::TempDir dir;
  const auto out = dir.path() / "out";
  const auto outcome = run_with_device_lost_at({"replay", "--quiet", animated_light_sequence().string()}, 1, out);
  expect_clean_error(outcome, 1, "the Vulkan device was lost during frame 1 (", out);
  EXPECT_NE(outcome.err.find("VK_ERROR_DEVICE_LOST"), std::string::npos) << outcome.err;
  EXPECT_NE(outcome.err.find("the outputs hold frame 0; --cpu runs without the GPU"), std::string::npos) << outcome.err;
  EXPECT_TRUE(std::filesystem::exists(out / "frames" / "000000_composite_mapped.png"));
  EXPECT_FALSE(std::filesystem::exists(out / "frames" / "000001_composite_mapped.png"));
  EXPECT_TRUE(std::filesystem::exists(out / "composite.mp4"));
  const auto report = read_report(out);
  EXPECT_EQ(report["frames"].get<int>(), 1);
  EXPECT_NE(report["stopped_by"].get<std::string>().find("device was lost"), std::string::npos) << report.dump();
}

// The same in live: the frames before the loss are finalised, then the line, exit 1.
TEST(DeviceRobustness, GpuLostDuringLive) {
  test::TempDir dir;
  const auto out = dir.path() / "out";
  const auto outcome = run_with_device_lost_at({"live", "--quiet", "--device", kDevice, "--frames", "5"}, 2, out);
  expect_clean_error(outcome, 1, "the Vulkan device was lost during frame 2 (", out);
  EXPECT_TRUE(std::filesystem::exists(out / "frames" / "000001_composite_mapped.png"));
  const auto report = read_report(out);
  EXPECT_EQ(report["frames"].get<int>(), 2);
}

std::optional<std::filesystem::path> temporary_recording(const std::filesystem::path& folder) {
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    if (entry.path().filename().string().find(".tmp-") != std::string::npos) return entry.path();
  }
  return std::nullopt;
}

// The device goes away after 2 frames: what was processed is finalised (report.json, frames),
// then one error line, exit 1.
TEST(DeviceRobustness, DeviceUnpluggedDuringLive) {
  test::TempDir dir;
  const auto out = dir.path() / "out";
  const auto run = run_relight({"live", "--quiet", "--device", kDevice + "&disconnect_after=2", "--frames", "10",
                                "--out", out.string()});
  expect_clean_error(run, 1, "disconnected", out);
  const auto report = read_report(out);
  // The second frame can be lost: the OpenNI2 core drops what the device sent last when it closes
  // the unplugged device while live is still busy with the first.
  EXPECT_GE(report["frames"].get<int>(), 1);
  EXPECT_LE(report["frames"].get<int>(), 2);
  EXPECT_NE(report["stopped_by"].get<std::string>().find("disconnected"), std::string::npos) << report.dump();
  EXPECT_TRUE(std::filesystem::exists(out / "frames" / "000000_color.png"));
}

// The same while recording: the .oni holds the frames read before, under its final name.
TEST(DeviceRobustness, DeviceUnpluggedDuringRecord) {
  test::TempDir dir;
  const auto oni = dir.path() / "take.oni";
  const auto run = run_relight({"record", "--quiet", "--device", kDevice + "&disconnect_after=3", "--frames", "10",
                                "--out", oni.string()});
  expect_clean_error(run, 1, "disconnected", dir.path());
  EXPECT_GE(capture::inspect_oni(oni).depth_frames, 2);
  const auto folder = dir.path() / "take";
  const auto to_folder = run_relight({"record", "--quiet", "--device", kDevice + "&disconnect_after=3", "--frames", "10",
                                      "--out", folder.string()});
  expect_clean_error(to_folder, 1, "disconnected", folder);
  // The device serves 3 frames on its own clock; a recorder slowed down by a loaded machine may
  // miss one (OpenNI keeps only the newest frame), but it keeps what it received.
  const std::size_t recorded = capture::TumSequence::open(folder).size();
  EXPECT_GE(recorded, 2u);
  EXPECT_LE(recorded, 3u);
}

// Unplugged after 2 frames and back 4 frame periods later: live waits (--reconnect-timeout),
// says so, goes on to the frames asked for and lists the reconnect in report.json.
TEST(DeviceRobustness, DeviceGoneAndBackDuringLive) {
  test::TempDir dir;
  const auto out = dir.path() / "out";
  const auto run = run_relight({"live", "--device", kDevice + "&disconnect_after=2&reconnect_after=4",
                                "--reconnect-timeout", "10", "--frames", "5", "--out", out.string()});
  expect_clean_success(run, out);
  EXPECT_NE(run.err.find("disconnected after "), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("; waiting up to 10.0 s for it to come back"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("is back after "), std::string::npos) << run.err;
  EXPECT_NE(run.err.find(" after an unplug; results in "), std::string::npos) << run.err;
  EXPECT_EQ(run.err.find("error"), std::string::npos) << run.err;
  const auto report = read_report(out);
  EXPECT_EQ(report["frames"].get<int>(), 5);
  EXPECT_EQ(report["stopped_by"], "end");
  // The device goes again after 2 frames of each connection: a second reconnect may come in.
  ASSERT_GE(report["reconnects"].size(), 1u) << report.dump();
  ASSERT_LE(report["reconnects"].size(), 2u) << report.dump();
  EXPECT_GE(report["reconnects"][0]["after_frames"].get<int>(), 1);
  EXPECT_LE(report["reconnects"][0]["after_frames"].get<int>(), 2);
  EXPECT_GT(report["reconnects"][0]["seconds_away"].get<double>(), 0.1);
  EXPECT_TRUE(std::filesystem::exists(out / "frames" / "000004_color.png"));
}

// Not back within --reconnect-timeout: finalised, then one error line, exit 1 (as without it).
TEST(DeviceRobustness, DeviceAwayPastTheReconnectTimeout) {
  test::TempDir dir;
  const auto out = dir.path() / "out";
  const auto run = run_relight({"live", "--quiet", "--device", kDevice + "&disconnect_after=2&reconnect_after=3000",
                                "--reconnect-timeout", "0.5", "--frames", "10", "--out", out.string()});
  expect_clean_error(run, 1, "did not come back within 0.5 s", out);
  const auto report = read_report(out);
  EXPECT_NE(report["stopped_by"].get<std::string>().find("did not come back"), std::string::npos) << report.dump();
  EXPECT_TRUE(report["reconnects"].empty());
  EXPECT_TRUE(std::filesystem::exists(out / "frames" / "000000_color.png"));
}

// Ctrl-C while live waits for the device: the run ends there as after any Ctrl-C, exit 0.
TEST(DeviceRobustness, CtrlCWhileWaitingForTheDevice) {
  test::TempDir dir;
  const auto out = dir.path() / "out";
  BoundedRun live;
  live.arguments = {"live",
                    "--device",
                    kDevice + "&disconnect_after=2&reconnect_after=3000",
                    "--reconnect-timeout",
                    "60",
                    "--frames",
                    "10",
                    "--out",
                    out.string()};
  // The device is gone after 2 frames (the second may be lost with it): 2.5 s after frame 0 is
  // out, live is waiting for it.
  std::optional<std::chrono::steady_clock::time_point> first_frame_out;
  live.interrupt_when = [&] {
    if (!first_frame_out && std::filesystem::exists(out / "frames" / "000000_color.png")) {
      first_frame_out = std::chrono::steady_clock::now();
    }
    return first_frame_out && std::chrono::steady_clock::now() - *first_frame_out > std::chrono::milliseconds(2500);
  };
  const auto run = run_relight(live);
  ASSERT_TRUE(run.interrupted) << describe(run);
  expect_clean_success(run, out);
  EXPECT_NE(run.err.find("waiting up to 60.0 s"), std::string::npos) << run.err;
  EXPECT_LT(run.seconds, 30.0) << describe(run);
  const auto report = read_report(out);
  EXPECT_EQ(report["stopped_by"], "interrupt");
  EXPECT_GE(report["frames"].get<int>(), 1);
  EXPECT_LE(report["frames"].get<int>(), 2);
}

// Ctrl-C once frame 1 is written: outputs finalised, no error, exit 0 (live runs until stopped).
TEST(DeviceRobustness, CtrlCDuringLive) {
  test::TempDir dir;
  const auto out = dir.path() / "out";
  BoundedRun live;
  live.arguments = {"live", "--quiet", "--device", kDevice, "--frames", "3000", "--out", out.string()};
  live.interrupt_when = [&] { return std::filesystem::exists(out / "frames" / "000001_color.png"); };
  const auto run = run_relight(live);
  ASSERT_TRUE(run.interrupted) << describe(run);
  expect_clean_success(run, out);
  EXPECT_EQ(run.err, "");
  const auto report = read_report(out);
  EXPECT_EQ(report["stopped_by"], "interrupt");
  EXPECT_GE(report["frames"].get<int>(), 2);
  EXPECT_LT(report["frames"].get<int>(), 3000);
}

// Ctrl-C while the recorder writes: the file is completed and renamed, nothing else is left.
TEST(DeviceRobustness, CtrlCDuringRecord) {
  test::TempDir dir;
  const auto oni = dir.path() / "take.oni";
  BoundedRun record;
  record.arguments = {"record", "--quiet", "--device", kDevice, "--frames", "3000", "--out", oni.string()};
  record.interrupt_when = [&] {
    const auto temporary = temporary_recording(dir.path());
    std::error_code ec;
    return temporary && std::filesystem::file_size(*temporary, ec) > 500'000;  // a few frames in
  };
  const auto run = run_relight(record);
  ASSERT_TRUE(run.interrupted) << describe(run);
  expect_clean_success(run, dir.path());
  EXPECT_EQ(run.err, "");
  EXPECT_GE(capture::inspect_oni(oni).depth_frames, 1);
  EXPECT_FALSE(temporary_recording(dir.path()));
}

TEST(DeviceRobustness, CutOrEmptyRecording) {
  test::TempDir dir;
  const auto oni = dir.path() / "take.oni";
  ASSERT_EQ(run_relight({"record", "--quiet", "--device", kDevice, "--frames", "4", "--out", oni.string()}).exit_code, 0);
  const std::string bytes = read_text_file(oni);
  const auto cut = dir.path() / "cut.oni";
  write_file_atomically(cut, bytes.substr(0, bytes.size() / 4));  // inside the frame data
  const auto empty = dir.path() / "empty.oni";
  write_file_atomically(empty, "");
  for (const auto& recording : {cut, empty, dir.path() / "missing.oni"}) {
    SCOPED_TRACE(recording.filename().string());
    const auto out = dir.path() / ("out_" + recording.stem().string());
    expect_clean_error(run_relight({"replay", "--quiet", "--cpu", recording.string(), "--out", out.string()}), 1,
                       recording.string(), out);
    EXPECT_FALSE(std::filesystem::exists(out / "report.json"));
  }
}

// A full disk while recording. OpenNI2's recorder drops what does not fit without an error; the
// read-back check turns that into one line naming the file and the full disk, and removes the
// file. A TUM folder's writer fails on the first file that does not fit.
TEST(DeviceRobustness, DiskFullDuringRecord) {
  test::TempDir dir;
  const auto out = dir.path() / "out";
  const TmpfsMount small_disk(out, "1m");
  if (!small_disk.mounted()) GTEST_SKIP() << small_disk.why_not();
  const auto oni = out / "recording.oni";
  const auto to_oni = run_relight({"record", "--quiet", "--device", kDevice, "--frames", "60", "--out", oni.string()});
  expect_clean_error(to_oni, 1, oni.string(), out);
  EXPECT_NE(to_oni.err.find("the disk holding it is full"), std::string::npos) << to_oni.err;
  EXPECT_EQ(to_oni.err.find("frame  of"), std::string::npos) << "a frame number is missing: " << to_oni.err;
  EXPECT_TRUE(std::filesystem::is_empty(out)) << "the cut recording is removed";

  const auto folder = out / "tum";
  const auto to_folder =
      run_relight({"record", "--quiet", "--device", kDevice, "--frames", "60", "--out", folder.string()});
  expect_clean_error(to_folder, 1, folder.string(), out);
  EXPECT_NE(to_folder.err.find("No space left on device"), std::string::npos) << to_folder.err;
}

}  // namespace
}  // namespace relight::robustness
