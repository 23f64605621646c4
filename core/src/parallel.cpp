#include "relight/core/parallel.h"

#include <algorithm>
#include <thread>

#include "relight/core/worker_pool.h"

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
  // A pool (TBB's arena, worker_pool.h) rather than threads started here: TBB keeps its workers
  // alive and lets the calling thread take any chunk nobody has started; starting and joining
  // threads on every call (what this did before) cost more than short per-frame loops on a loaded
  // machine (K-means: 146 ms against 56 ms).
  WorkerPool(std::min(worker_count(threads), chunks)).for_ranges(rows, work, grain);
}

}  // namespace relight
