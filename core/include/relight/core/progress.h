#pragma once
// A one-line progress bar on stderr for long runs: frame count, fps and ETA. It stays silent when
// stderr is not a terminal, when asked to be quiet, and during the first second of a run (short
// runs print nothing).
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <string>

namespace relight {

class ProgressBar {
 public:
  /// total = 0 when the number of frames is unknown (live capture): no ETA then.
  ProgressBar(std::string label, std::int64_t total, bool quiet);
  ~ProgressBar();
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  void update(std::int64_t done);
  /// Ends the line (if one was drawn).
  void finish();

  /// The text of the bar, exposed for tests.
  [[nodiscard]] static std::string format(const std::string& label, std::int64_t done, std::int64_t total,
                                          double elapsed_seconds, int width = 28);

 private:
  std::string label_;
  std::int64_t total_;
  bool enabled_;
  bool drawn_ = false;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
};

}  // namespace relight
