#include "relight/core/worker_pool.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "relight/core/cpu_dispatch.h"
#include "relight/core/parallel.h"

#ifndef RELIGHT_THREAD_SANITIZER
#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>
#endif

namespace relight {

#ifndef RELIGHT_THREAD_SANITIZER

struct WorkerPool::Arena {
  explicit Arena(int threads) : arena(threads) {}
  tbb::task_arena arena;
};

WorkerPool::WorkerPool(int threads) : threads_(worker_count(threads)), arena_(std::make_unique<Arena>(threads_)) {}

void WorkerPool::for_ranges(int count, const std::function<void(int, int)>& work, int grain) {
  if (count <= 0) return;
  grain = std::max(1, grain);
  arena_->arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, count, static_cast<std::size_t>(grain)),
                      [&](const tbb::blocked_range<int>& range) { work(range.begin(), range.end()); });
  });
}

#else

struct WorkerPool::Arena {};

WorkerPool::WorkerPool(int threads) : threads_(worker_count(threads)) {}

void WorkerPool::for_ranges(int count, const std::function<void(int, int)>& work, int grain) {
  if (count <= 0) return;
  grain = std::max(1, grain);
  const int chunks = (count + grain - 1) / grain;
  std::atomic<int> next_chunk{0};
  std::atomic<bool> failed{false};
  std::mutex failure_mutex;
  std::exception_ptr failure;
  const auto drain = [&] {
    for (int chunk = next_chunk++; chunk < chunks && !failed; chunk = next_chunk++) {
      try {
        work(chunk * grain, std::min(count, (chunk + 1) * grain));
      } catch (...) {
        const std::scoped_lock lock(failure_mutex);
        if (!failure) failure = std::current_exception();
        failed = true;
      }
    }
  };
  {
    std::vector<std::jthread> helpers;
    for (int t = 1; t < std::min(threads_, chunks); ++t) helpers.emplace_back(drain);
    drain();
  }  // joined
  if (failure) std::rethrow_exception(failure);
}

#endif

WorkerPool::~WorkerPool() = default;
WorkerPool::WorkerPool(WorkerPool&&) noexcept = default;
WorkerPool& WorkerPool::operator=(WorkerPool&&) noexcept = default;

}  // namespace relight
