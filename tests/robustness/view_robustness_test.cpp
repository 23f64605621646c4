// Robustness matrix, the --view window: Ctrl-C during `relight live --view` finalises the outputs
// as without the window, and Ctrl-C while the window is paused (space) ends the run too, though
// the pipeline waits for the window there. The window opens on a virtual X server (Xvfb); the
// pause is a key press on it (xdotool).
#include <gtest/gtest.h>

#include <chrono>
#include <nlohmann/json.hpp>
#include <optional>

#include "inputs.h"
#include "outcome_checks.h"
#include "support/virtual_display.h"

namespace relight::robustness {
namespace {

const std::string kDevice = "relight://synthetic?size=320x240";

std::size_t frames_written(const std::filesystem::path& out) {
  std::size_t count = 0;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(out / "frames", ec)) {
    count += entry.path().filename().string().ends_with("_color.png") ? 1 : 0;
  }
  return count;
}

class ViewRobustness : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_FALSE(screen.display().empty()) << "Xvfb (Debian package xvfb) did not start: " << screen.log();
  }
  BoundedRun live_with_view() const {
    BoundedRun live;
    live.arguments = {"live", "--quiet", "--view", "--device", kDevice, "--frames", "3000", "--out", out.string()};
    live.environment = {{"DISPLAY", screen.display()}};
    return live;
  }
  void expect_stopped_by_interrupt(const RunOutcome& run) {
    ASSERT_TRUE(run.interrupted) << describe(run);
    expect_clean_success(run, out);
    EXPECT_EQ(run.err, "");
    ASSERT_TRUE(std::filesystem::exists(out / "report.json"));
    const auto report = nlohmann::json::parse(read_text_file(out / "report.json"));
    EXPECT_EQ(report["stopped_by"], "interrupt");
    EXPECT_GE(report["view"]["drawn"].get<int>(), 1) << report.dump();
  }

  test::VirtualDisplay screen;
  test::TempDir dir;
  std::filesystem::path out = dir.path() / "out";
};

TEST_F(ViewRobustness, CtrlCDuringLiveWithTheView) {
  BoundedRun live = live_with_view();
  live.interrupt_when = [&] { return std::filesystem::exists(out / "frames" / "000001_color.png"); };
  expect_stopped_by_interrupt(run_relight(live));
}

// Paused, the pipeline waits inside the view stage for the window; Ctrl-C must end that wait (it
// once waited for the space bar, with the run hanging until SIGKILL).
TEST_F(ViewRobustness, CtrlCWhileTheViewIsPaused) {
  BoundedRun live = live_with_view();
  using Clock = std::chrono::steady_clock;
  std::optional<Clock::time_point> paused_at;
  std::optional<std::size_t> frames_soon_after_pause;
  std::size_t frames_later = 0;
  bool pressed = false;
  Clock::time_point interrupted_at;
  live.interrupt_when = [&] {
    if (!paused_at) {
      if (!std::filesystem::exists(out / "frames" / "000001_color.png")) return false;
      pressed = screen.press("relight live", "space");
      paused_at = Clock::now();
      return false;
    }
    const auto since = Clock::now() - *paused_at;
    // A frame in flight when the key came may still be written: count from 1.5 s on.
    if (!frames_soon_after_pause && since > std::chrono::milliseconds(1500))
      frames_soon_after_pause = frames_written(out);
    if (since < std::chrono::milliseconds(3000)) return false;
    frames_later = frames_written(out);
    interrupted_at = Clock::now();
    return true;
  };
  const auto run = run_relight(live);
  const double seconds_to_stop = std::chrono::duration<double>(Clock::now() - interrupted_at).count();
  ASSERT_TRUE(pressed) << "xdotool (Debian package xdotool) found no window named 'relight live'";
  ASSERT_TRUE(frames_soon_after_pause);
  EXPECT_EQ(frames_later, *frames_soon_after_pause) << "the pause did not stop the pipeline";
  expect_stopped_by_interrupt(run);
  EXPECT_LT(seconds_to_stop, 15.0) << describe(run);
}

}  // namespace
}  // namespace relight::robustness
