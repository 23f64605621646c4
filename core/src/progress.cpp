#include "relight/core/progress.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>

namespace relight {

ProgressBar::ProgressBar(std::string label, std::int64_t total, bool quiet)
    : label_(std::move(label)), total_(total), enabled_(!quiet && ::isatty(STDERR_FILENO) == 1),
      start_(std::chrono::steady_clock::now()), last_draw_(start_) {}

ProgressBar::~ProgressBar() { finish(); }

std::string ProgressBar::format(const std::string& label, std::int64_t done, std::int64_t total,
                                double elapsed_seconds, int width) {
  const double fps = elapsed_seconds > 0 ? static_cast<double>(done) / elapsed_seconds : 0.0;
  char numbers[96];
  std::string line = label + " ";
  if (total > 0) {
    const double fraction = std::clamp(static_cast<double>(done) / static_cast<double>(total), 0.0, 1.0);
    const int filled = static_cast<int>(std::lround(fraction * width));
    line += "[" + std::string(static_cast<std::size_t>(filled), '#') +
            std::string(static_cast<std::size_t>(width - filled), '.') + "] ";
    const double eta = fps > 0 ? static_cast<double>(total - done) / fps : 0.0;
    std::snprintf(numbers, sizeof numbers, "%lld/%lld frames  %.1f fps  ETA %.0fs", static_cast<long long>(done),
                  static_cast<long long>(total), fps, eta);
  } else {
    std::snprintf(numbers, sizeof numbers, "%lld frames  %.1f fps", static_cast<long long>(done), fps);
  }
  return line + numbers;
}

void ProgressBar::update(std::int64_t done) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const bool due = std::chrono::duration<double>(now - last_draw_).count() >= 0.1 || done == total_;
  if (elapsed < 1.0 || !due) return;
  last_draw_ = now;
  drawn_ = true;
  std::fprintf(stderr, "\r%s\033[K", format(label_, done, total_, elapsed).c_str());
  std::fflush(stderr);
}

void ProgressBar::finish() {
  if (!drawn_) return;
  std::fputc('\n', stderr);
  drawn_ = false;
}

}  // namespace relight
