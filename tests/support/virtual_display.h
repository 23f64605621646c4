#pragma once
// A virtual X server (Xvfb) for the tests of `--view`: it picks its own display number, mirrors
// its screen into an XWD file the test reads as a screenshot, and takes key presses (xdotool)
// for the window the relight process opens on it. Debian packages xvfb and xdotool.
#include <signal.h>

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <string>
#include <thread>

#include "relight/core/atomic_file.h"
#include "relight/core/image.h"
#include "temp_dir.h"

namespace relight::test {

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

  /// ":N", or empty when Xvfb did not start (log() says why).
  [[nodiscard]] const std::string& display() const { return display_; }
  [[nodiscard]] std::string log() const { return read_text_file(dir_.path() / "log"); }

  /// Gives the keyboard focus to the first window whose title contains `title` and presses `key`
  /// (an X keysym name: "space", "q") there. No window manager runs, so the focus is set
  /// explicitly. False when no such window exists or xdotool is missing.
  [[nodiscard]] bool press(const std::string& title, const std::string& key) const {
    const std::string command = "DISPLAY=" + display_ + " xdotool search --name '" + title +
                                "' windowfocus --sync key " + key + " >/dev/null 2>&1";
    return std::system(command.c_str()) == 0;
  }

  /// The screen now (XWD, ZPixmap, 32 bits a pixel, colour masks from the header); empty when
  /// the file is not (yet) complete.
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
  static std::uint32_t big_endian(const std::string& bytes, std::size_t at) {
    return (std::uint32_t{static_cast<unsigned char>(bytes[at])} << 24) |
           (std::uint32_t{static_cast<unsigned char>(bytes[at + 1])} << 16) |
           (std::uint32_t{static_cast<unsigned char>(bytes[at + 2])} << 8) | static_cast<unsigned char>(bytes[at + 3]);
  }

  TempDir dir_;
  std::string display_;
  int pid_ = 0;
};

}  // namespace relight::test
