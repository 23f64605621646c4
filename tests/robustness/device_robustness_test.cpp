// Robustness matrix, devices: no Vulkan driver at all (the CPU path, with one warning), relight's
// OpenNI2 device (relight://synthetic) unplugged mid-stream or stopped with Ctrl-C during live and
// record, cut or empty .oni recordings, a disk that fills up while recording.
#include <gtest/gtest.h>

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
  EXPECT_TRUE(std::filesystem::exists(out / "frames" / "000001_composite.png"));
  EXPECT_TRUE(std::filesystem::exists(out / "composite.mp4"));
}

nlohmann::json read_report(const std::filesystem::path& folder) {
  return nlohmann::json::parse(read_text_file(folder / "report.json"));
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

// Ctrl-C once frame 1 is written: outputs finalised, no error, exit 0 (live runs until stopped).
TEST(DeviceRobustness, CtrlCDuringLive) {
  test::TempDir dir;
  const auto out = dir.path() / "out";
  BoundedRun live;
  live.arguments = {"live", "--quiet", "--device", kDevice, "--frames", "3000", "--out", out.string()};
  live.interrupt_when = [&] { return std::filesystem::exists(out / "frames" / "000001_normals.png"); };
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
