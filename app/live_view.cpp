#include "live_view.h"

#include <SDL.h>

#include <chrono>
#include <cstdlib>
#include <cstdio>
#include <future>
#include <iostream>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "relight/core/error.h"
#include "relight/core/image_io.h"

namespace relight::app {

namespace {

struct WindowDeleter {
  void operator()(SDL_Window* window) const { SDL_DestroyWindow(window); }
};
struct RendererDeleter {
  void operator()(SDL_Renderer* renderer) const { SDL_DestroyRenderer(renderer); }
};
struct TextureDeleter {
  void operator()(SDL_Texture* texture) const { SDL_DestroyTexture(texture); }
};
using Window = std::unique_ptr<SDL_Window, WindowDeleter>;
using Renderer = std::unique_ptr<SDL_Renderer, RendererDeleter>;
using Texture = std::unique_ptr<SDL_Texture, TextureDeleter>;

/// `overlay`'s lines in white with a dark outline (readable on any picture), top-left.
void draw_overlay(ColorImage& picture, const std::string& overlay) {
  cv::Mat mat(picture.height(), picture.width(), CV_8UC3, static_cast<void*>(picture.pixels().data()));
  const double scale = picture.width() >= 640 ? 0.5 : 0.4;
  const int line_height = picture.width() >= 640 ? 18 : 14;
  std::istringstream lines(overlay);
  int y = line_height;
  for (std::string line; std::getline(lines, line); y += line_height) {
    cv::putText(mat, line, {6, y}, cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(0, 0, 0), 3, cv::LINE_AA);
    cv::putText(mat, line, {6, y}, cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  }
}

/// The view is the process's only SDL user, so it shuts SDL down entirely: only SDL_Quit closes
/// SDL's D-Bus connection and frees its hints, which SDL_QuitSubSystem leaves (LeakSanitizer).
void shut_down_sdl() {
  SDL_QuitSubSystem(SDL_INIT_VIDEO);
  SDL_Quit();
}

}  // namespace

LiveView::LiveView(std::string title, std::filesystem::path snapshot_folder)
    : snapshot_folder_(std::move(snapshot_folder)) {
  std::promise<std::string> opened;
  auto result = opened.get_future();
  thread_ = std::thread([this, title = std::move(title), &opened]() mutable { display_loop(std::move(title), &opened); });
  const std::string error = result.get();
  if (!error.empty()) {
    thread_.join();
    throw Error("--view needs a display: " + error);
  }
}

LiveView::~LiveView() {
  stop_ = true;
  changed_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void LiveView::show(ColorImage picture, std::string overlay) {
  {
    std::lock_guard lock(mutex_);
    if (pending_) ++skipped_;
    pending_ = Pending{std::move(picture), std::move(overlay)};
  }
  changed_.notify_all();
}

void LiveView::wait_while_paused(const std::function<bool()>& give_up) {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [this, &give_up] { return !paused_ || quit_ || stop_ || give_up(); });
}

void LiveView::snapshot(const ColorImage& shown) {
  char name[48];
  std::snprintf(name, sizeof name, "view_%04lld.png", static_cast<long long>(snapshots_++));
  std::error_code ec;
  std::filesystem::create_directories(snapshot_folder_, ec);
  try {
    write_color(snapshot_folder_ / name, shown);
    std::cerr << "\nrelight: snapshot " << (snapshot_folder_ / name).string() << "\n";
  } catch (const Error& error) {
    std::cerr << "\nrelight: warning: snapshot failed: " << error.what() << "\n";  // the run goes on
  }
}

void LiveView::display_loop(std::string title, std::promise<std::string>* opened) {
  const auto set = [](const char* name) { return std::getenv(name) && *std::getenv(name); };
  if (!set("DISPLAY") && !set("WAYLAND_DISPLAY") && !set("SDL_VIDEODRIVER")) {
    opened->set_value("neither DISPLAY nor WAYLAND_DISPLAY is set");  // before SDL probes and prints
    return;
  }
  // SDL would otherwise turn Ctrl-C into a window-close event; the commands handle it themselves.
  SDL_SetHint(SDL_HINT_NO_SIGNAL_HANDLERS, "1");
  if (SDL_InitSubSystem(SDL_INIT_VIDEO) != 0) {
    opened->set_value(SDL_GetError());
    return;
  }
  // Without a display SDL falls back to drivers that draw nowhere; a window nobody can see is
  // an error unless SDL_VIDEODRIVER asked for it.
  const std::string driver = SDL_GetCurrentVideoDriver() ? SDL_GetCurrentVideoDriver() : "";
  const char* requested = std::getenv("SDL_VIDEODRIVER");
  if ((driver == "offscreen" || driver == "dummy" || driver == "evdev" || driver == "KMSDRM") &&
      !(requested && driver == requested)) {
    shut_down_sdl();
    opened->set_value("no window system, SDL found only its '" + driver + "' video driver");
    return;
  }
  opened->set_value("");
  {
    Window window;
    Renderer renderer;
    Texture texture;
    int texture_width = 0, texture_height = 0;
    std::optional<Pending> shown;  // the last picture drawn, without its overlay
    ColorImage with_overlay;
    const auto present = [&] {
      if (!shown) return;
      with_overlay = shown->picture;
      draw_overlay(with_overlay, shown->overlay + (paused_ ? "\nPAUSED (space resumes, s snapshot, q quits)" : ""));
      if (!window) {
        window.reset(SDL_CreateWindow(title.c_str(), SDL_WINDOWPOS_CENTERED, SDL_WINDOWPOS_CENTERED,
                                      with_overlay.width(), with_overlay.height(), SDL_WINDOW_RESIZABLE));
        if (!window) throw Error(std::string("--view: cannot open a window: ") + SDL_GetError());
        renderer.reset(SDL_CreateRenderer(window.get(), -1, 0));
        if (!renderer) renderer.reset(SDL_CreateRenderer(window.get(), -1, SDL_RENDERER_SOFTWARE));
        if (!renderer) throw Error(std::string("--view: cannot draw into the window: ") + SDL_GetError());
      }
      if (!texture || texture_width != with_overlay.width() || texture_height != with_overlay.height()) {
        texture.reset(SDL_CreateTexture(renderer.get(), SDL_PIXELFORMAT_RGB24, SDL_TEXTUREACCESS_STREAMING,
                                        with_overlay.width(), with_overlay.height()));
        texture_width = with_overlay.width();
        texture_height = with_overlay.height();
        SDL_SetWindowSize(window.get(), texture_width, texture_height);
        SDL_RenderSetLogicalSize(renderer.get(), texture_width, texture_height);  // resizing keeps the aspect
      }
      SDL_UpdateTexture(texture.get(), nullptr, with_overlay.pixels().data(), 3 * with_overlay.width());
      SDL_RenderClear(renderer.get());
      SDL_RenderCopy(renderer.get(), texture.get(), nullptr, nullptr);
      SDL_RenderPresent(renderer.get());
    };
    try {
      while (!stop_) {
        bool redraw = false;
        for (SDL_Event event; SDL_PollEvent(&event);) {
          if (event.type == SDL_QUIT ||
              (event.type == SDL_WINDOWEVENT && event.window.event == SDL_WINDOWEVENT_CLOSE)) {
            quit_ = true;
          } else if (event.type == SDL_WINDOWEVENT && event.window.event == SDL_WINDOWEVENT_EXPOSED) {
            redraw = true;
          } else if (event.type == SDL_KEYDOWN) {
            const SDL_Keycode key = event.key.keysym.sym;
            if (key == SDLK_q || key == SDLK_ESCAPE) quit_ = true;
            if (key == SDLK_SPACE) {
              paused_ = !paused_;
              redraw = true;
            }
            if (key == SDLK_s && shown) snapshot(with_overlay);
          }
          if (quit_) changed_.notify_all();
        }
        std::optional<Pending> next;
        {
          std::unique_lock lock(mutex_);
          changed_.wait_for(lock, std::chrono::milliseconds(15), [this] { return pending_.has_value() || stop_.load(); });
          next.swap(pending_);
        }
        if (next) {
          shown = std::move(next);
          ++drawn_;
          redraw = true;
        }
        if (redraw) present();
        changed_.notify_all();  // a resumed pause
      }
    } catch (const Error& error) {
      std::cerr << "\nrelight: warning: " << error.what() << "; the run goes on without the view\n";
    }
  }
  shut_down_sdl();
}

}  // namespace relight::app
