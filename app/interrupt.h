#pragma once
// Ctrl-C (SIGINT) and SIGTERM as a flag that long-running commands poll between frames, so that
// they stop cleanly: outputs finalised, device closed. The previous handlers come back when the
// guard goes out of scope.
#include <csignal>

namespace relight::app {

class InterruptGuard {
 public:
  InterruptGuard();
  ~InterruptGuard();
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;
  /// True once SIGINT or SIGTERM arrived while a guard was installed.
  [[nodiscard]] static bool interrupted();

 private:
  struct sigaction previous_int_ {};
  struct sigaction previous_term_ {};
};

}  // namespace relight::app
