#include "relight/core/parallel.h"

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>

#include <algorithm>
#include <thread>

namespace relight {

int worker_count(int requested) {
  if (requested > 0) return requested;
  return static_cast<int>(std::clamp(std::thread::hardware_concurrency(), 1u, 8u));
}

void parallel_rows(int rows, int threads, const std::function<void(int, int)>& work, int grain) {
  if (rows <= 0) return;
  grain = std::max(1, grain);
  const int chunks = (rows + grain - 1) / grain;
  if (threads == 1 || chunks < 2) {
    work(0, rows);
    return;
  }
  // TBB keeps its workers alive and lets the calling thread take any chunk nobody has started;
  // starting and joining threads on every call (what this did before) cost more than short
  // per-frame loops on a loaded machine (K-means: 146 ms against 56 ms). Exceptions propagate
  // to the caller after the other chunks are cancelled.
  const auto run = [&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, rows, static_cast<std::size_t>(grain)),
                      [&](const tbb::blocked_range<int>& range) { work(range.begin(), range.end()); });
  };
  tbb::task_arena arena(std::min(worker_count(threads), chunks));
  arena.execute(run);
}

}  // namespace relight
