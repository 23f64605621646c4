// `relight replay --view`: the window shows the composite as it is made. The test runs the
// replay on a virtual X server (Xvfb, whose framebuffer it reads as an XWD file) and checks that
// a screenshot taken while the run goes on shows the composite - the pebble's pixels as the
// composite has them, not as the camera saw them - and that --view without a display is a
// one-line error.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <nlohmann/json.hpp>
#include <thread>
#include <vector>

#include "cli.h"
#include "relight/core/atomic_file.h"
#include "relight/core/image_io.h"
#include "support/virtual_display.h"
#include "temp_dir.h"

namespace relight::app {
namespace {

using cli_test::expect_one_line_error;
using cli_test::relight;
using test::VirtualDisplay;

/// Mean channel difference between `screen` at (x, y) and `picture`, over the pixels `use` picks.
template <class Use>
double mean_difference(const ColorImage& screen, int x, int y, const ColorImage& picture, Use use) {
  double sum = 0;
  std::size_t count = 0;
  for (int r = 0; r < picture.height(); ++r) {
    for (int c = 0; c < picture.width(); ++c) {
      if (!use(r, c) || y + r >= screen.height() || x + c >= screen.width()) continue;
      const Rgb8 a = screen(y + r, x + c), b = picture(r, c);
      sum += std::abs(a.r - b.r) + std::abs(a.g - b.g) + std::abs(a.b - b.b);
      count += 3;
    }
  }
  return count ? sum / static_cast<double>(count) : 255.0;
}

TEST(ViewCli, TheWindowShowsTheCompositeAsItIsMade) {
  VirtualDisplay screen;
  ASSERT_FALSE(screen.display().empty()) << "Xvfb (Debian package xvfb) did not start: " << screen.log();
  test::TempDir dir;
  const auto sequence =
      cli_test::synthetic_sequence("--frames 2 --trajectory static --noise none --size 320x240 --no-gt");
  const auto out = dir.path() / "out";
  const std::string pebble = std::string(RELIGHT_TEST_DATA) + "/models/glossy_pebble.gltf";
  const std::string run = "DISPLAY=" + screen.display() + " " + RELIGHT_BIN + " replay --quiet --view --buffers --no-video --vpls 8 --loop 8 " +
                          sequence.string() + " --object " + pebble + " --out " + out.string();
  const auto rc_file = dir.path() / "rc";
  ASSERT_EQ(std::system(("(" + run + " 2>" + (dir.path() / "err").string() + "; echo $? >" + rc_file.string() + ") &").c_str()), 0);
  // Screenshots while the replay runs (the window closes with it).
  std::vector<ColorImage> shots;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(3);
  while (!std::filesystem::exists(rc_file) && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    if (std::filesystem::exists(out / "frames" / "000000_composite_mapped.png")) shots.push_back(screen.screenshot());
  }
  ASSERT_TRUE(std::filesystem::exists(rc_file)) << "the replay did not finish";
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  ASSERT_EQ(read_text_file(rc_file), "0\n") << read_text_file(dir.path() / "err");
  ASSERT_FALSE(shots.empty());

  // The static camera sees the same view every frame: frame 0's composite is what the window shows.
  const ColorImage composite = read_color(out / "frames" / "000000_composite_mapped.png");
  const ColorImage camera = read_color(out / "frames" / "000000_color.png");
  const ColorImage coverage = read_color(out / "frames" / "000000_virtual_coverage.png");
  const auto pebble_pixel = [&](int r, int c) { return coverage(r, c).r > 200; };
  const auto below_overlay = [](int r, int) { return r >= 70; };  // the text sits in the top-left corner
  const double pebble_changed = mean_difference(camera, 0, 0, composite, pebble_pixel);
  ASSERT_GT(pebble_changed, 20.0) << "the pebble must stand out from the camera image for the test to mean anything";
  double best = 255, best_pebble = 255;
  for (const ColorImage& shot : shots) {
    // No window manager: SDL centres the window (800x600 screen).
    for (int dy = -2; dy <= 2; ++dy) {
      for (int dx = -2; dx <= 2; ++dx) {
        const int x = (800 - composite.width()) / 2 + dx, y = (600 - composite.height()) / 2 + dy;
        const double whole = mean_difference(shot, x, y, composite, below_overlay);
        if (whole < best) {
          best = whole;
          best_pebble = mean_difference(shot, x, y, composite, pebble_pixel);
        }
      }
    }
  }
  std::printf("%zu screenshots; best match: %.2f per channel overall, %.2f on the pebble (camera vs composite there: %.1f)\n",
              shots.size(), best, best_pebble, pebble_changed);
  EXPECT_LT(best, 6.0);
  EXPECT_LT(best_pebble, 0.3 * pebble_changed);
  const auto report = nlohmann::json::parse(read_text_file(out / "report.json"));
  EXPECT_GE(report["view"]["drawn"].get<int>(), 1) << report["view"].dump();
}

TEST(ViewCli, ViewWithoutADisplayIsAOneLineError) {
  test::TempDir dir;
  const auto result = test::run_command("env -u DISPLAY -u WAYLAND_DISPLAY " + std::string(RELIGHT_BIN) +
                                        " replay --quiet --view --frames 0:1 --out " + (dir.path() / "out").string());
  expect_one_line_error(result, 1);
  EXPECT_NE(result.err.find("--view needs a display"), std::string::npos) << result.err;
}

}  // namespace
}  // namespace relight::app
