// `relight replay --view`: the window shows the composite as it is made. The test runs the
// replay on a virtual X server (Xvfb, whose framebuffer it reads as an XWD file) and checks that
// a screenshot taken while the run goes on shows the composite - the pebble's pixels as the
// composite has them, not as the camera saw them - and that --view without a display is a
// one-line error.
#include <gtest/gtest.h>
#include <signal.h>

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
#include "temp_dir.h"

namespace relight::app {
namespace {

using cli_test::expect_one_line_error;
using cli_test::relight;

std::uint32_t big_endian(const std::string& bytes, std::size_t at) {
  return (std::uint32_t{static_cast<unsigned char>(bytes[at])} << 24) |
         (std::uint32_t{static_cast<unsigned char>(bytes[at + 1])} << 16) |
         (std::uint32_t{static_cast<unsigned char>(bytes[at + 2])} << 8) | static_cast<unsigned char>(bytes[at + 3]);
}

/// An Xvfb server on a display it picks itself, its screen mirrored into an XWD file.
class VirtualDisplay {
 public:
  VirtualDisplay() {
    const auto folder = dir_.path();
    const std::string command = "Xvfb -displayfd 3 -screen 0 800x600x24 -nolisten tcp -fbdir " + folder.string() +
                                " 3>" + (folder / "display").string() + " 2>" + (folder / "log").string() +
                                " </dev/null & echo $! >" + (folder / "pid").string();
    if (std::system(command.c_str()) != 0) return;
    for (int wait = 0; wait < 100 && display_.empty(); ++wait) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
      std::ifstream in(folder / "display");
      std::string number;
      if (in >> number) display_ = ":" + number;
    }
    std::ifstream(folder / "pid") >> pid_;
  }
  ~VirtualDisplay() {
    if (pid_ > 0) kill(pid_, SIGTERM);
  }
  VirtualDisplay(const VirtualDisplay&) = delete;
  VirtualDisplay& operator=(const VirtualDisplay&) = delete;

  [[nodiscard]] const std::string& display() const { return display_; }
  [[nodiscard]] std::string log() const { return read_text_file(dir_.path() / "log"); }

  /// The screen now (XWD, ZPixmap, 32 bits a pixel, colour masks from the header).
  [[nodiscard]] ColorImage screenshot() const {
    std::ifstream in(dir_.path() / "Xvfb_screen0", std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (bytes.size() < 100) return {};
    const auto field = [&bytes](int index) { return big_endian(bytes, 4 * static_cast<std::size_t>(index)); };
    const std::uint32_t header = field(0), width = field(4), height = field(5), byte_order = field(7);
    const std::uint32_t bits = field(11), bytes_per_line = field(12), colors = field(19);
    const std::uint32_t masks[3] = {field(14), field(15), field(16)};  // after visual_class (13)
    const std::size_t data = header + 12 * static_cast<std::size_t>(colors);
    if (bits != 32 || bytes.size() < data + static_cast<std::size_t>(bytes_per_line) * height) return {};
    ColorImage image(static_cast<int>(width), static_cast<int>(height));
    for (std::uint32_t r = 0; r < height; ++r) {
      for (std::uint32_t c = 0; c < width; ++c) {
        const std::size_t at = data + static_cast<std::size_t>(r) * bytes_per_line + 4 * c;
        std::uint32_t pixel = 0;
        for (int b = 0; b < 4; ++b) {
          const std::uint32_t byte = static_cast<unsigned char>(bytes[at + static_cast<std::size_t>(b)]);
          pixel |= byte_order == 0 ? byte << (8 * b) : byte << (8 * (3 - b));  // 0: LSBFirst
        }
        std::uint8_t channel[3];
        for (int k = 0; k < 3; ++k) {
          int shift = 0;
          while (shift < 32 && !((masks[k] >> shift) & 1u)) ++shift;
          channel[k] = static_cast<std::uint8_t>((pixel & masks[k]) >> shift);
        }
        image(static_cast<int>(r), static_cast<int>(c)) = Rgb8{channel[0], channel[1], channel[2]};
      }
    }
    return image;
  }

 private:
  test::TempDir dir_;
  std::string display_;
  int pid_ = 0;
};

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
