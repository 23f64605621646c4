#pragma once
// `--view`: a window that shows the pipeline's picture as it is made (SDL2), with the frame, fps,
// tracking state and dropped frames written over it. Keys: q / Esc (or closing the window)
// quit - the run stops after the current frame and finalises its outputs, as on Ctrl-C; space
// pauses and resumes; s writes the picture shown, overlay included, to the snapshot folder.
//
// The window lives on a display thread of its own, which is the only one that calls SDL: the
// pipeline hands a picture over (show(), a copy into a one-picture mailbox) and goes on, so a
// slow display skips pictures instead of slowing the pipeline; how many it skipped is counted.
// SDL2 rather than OpenCV's highgui (whose Debian build is Qt's, with its own thread rules):
// plain event polling from one thread, and a path to a Vulkan surface (SDL_Vulkan_CreateSurface)
// that avoids the read-back on a real GPU.
#include <atomic>
#include <condition_variable>
#include <filesystem>
#include <functional>
#include <future>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "relight/core/image.h"

namespace relight::app {

class LiveView {
 public:
  /// Opens the window system (not yet the window: it takes the first picture's size). Throws
  /// relight::Error, naming SDL's reason, when there is no display.
  LiveView(std::string title, std::filesystem::path snapshot_folder);
  ~LiveView();
  LiveView(const LiveView&) = delete;
  LiveView& operator=(const LiveView&) = delete;

  /// Hands `picture` to the display with `overlay` (lines separated by '\n') written over its
  /// top-left corner; returns at once. A picture not yet drawn is replaced (counted as skipped).
  void show(ColorImage picture, std::string overlay);
  /// Blocks while the view is paused (space), until resumed, quit or `give_up()` (Ctrl-C: the
  /// commands' signal flag, which no one notifies; polled at the display loop's 15 ms pace).
  void wait_while_paused(const std::function<bool()>& give_up);
  [[nodiscard]] bool quit_requested() const { return quit_.load(); }
  [[nodiscard]] bool paused() const { return paused_.load(); }
  /// Pictures the display replaced before drawing them.
  [[nodiscard]] std::int64_t skipped() const { return skipped_.load(); }
  [[nodiscard]] std::int64_t drawn() const { return drawn_.load(); }

 private:
  struct Pending {
    ColorImage picture;
    std::string overlay;
  };
  void display_loop(std::string title, std::promise<std::string>* opened);
  void snapshot(const ColorImage& shown);

  std::filesystem::path snapshot_folder_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::optional<Pending> pending_;
  std::atomic<bool> stop_{false}, quit_{false}, paused_{false};
  std::atomic<std::int64_t> skipped_{0}, drawn_{0}, snapshots_{0};
  std::thread thread_;
};

}  // namespace relight::app
