#include "relight/core/parallel.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace relight {

int worker_count(int requested) {
  if (requested > 0) return requested;
  return static_cast<int>(std::clamp(std::thread::hardware_concurrency(), 1u, 8u));
}

void parallel_rows(int rows, int threads, const std::function<void(int, int)>& work, int grain) {
  if (rows <= 0) return;
  grain = std::max(1, grain);
  const int chunks = (rows + grain - 1) / grain;
  const int workers = std::min(worker_count(threads), chunks);
  if (workers <= 1) {
    work(0, rows);
    return;
  }
  std::atomic<int> next_chunk{0};
  std::exception_ptr failure;
  std::mutex failure_mutex;
  auto drain = [&] {
    try {
      for (int chunk = next_chunk++; chunk < chunks; chunk = next_chunk++) {
        work(chunk * grain, std::min(rows, (chunk + 1) * grain));
      }
    } catch (...) {
      const std::lock_guard lock(failure_mutex);
      if (!failure) failure = std::current_exception();
      next_chunk = chunks;
    }
  };
  std::vector<std::jthread> helpers;
  helpers.reserve(static_cast<std::size_t>(workers - 1));
  for (int i = 1; i < workers; ++i) helpers.emplace_back(drain);
  drain();
  helpers.clear();  // joins
  if (failure) std::rethrow_exception(failure);
}

}  // namespace relight
