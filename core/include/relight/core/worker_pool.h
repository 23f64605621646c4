#pragma once
// A pool of worker threads for repeated parallel loops over index ranges (parallel_rows, the
// K-means step). In normal builds it is a TBB task arena: its workers stay alive between calls
// and the calling thread takes any chunk that no worker has started, so short per-frame loops
// cost no thread start-up.
//
// Under ThreadSanitizer (the tsan preset) it runs the same chunks on std::threads that pull chunk
// indices from an atomic counter, then joins them. Why: Debian's libtbb is not instrumented, so
// TSan cannot see the hand-off between a TBB worker finishing a chunk and the caller reading its
// output, and reports every parallel loop as a race inside TBB's headers; suppressing those
// reports would also hide real races in our loop bodies, which run under TBB's frames. With plain
// threads TSan sees every hand-off and checks exactly our code: the chunk bodies and what the
// caller does with their results.
#include <functional>
#include <memory>

namespace relight {

class WorkerPool {
 public:
  /// `threads` workers including the calling thread (0 = worker_count(0)).
  explicit WorkerPool(int threads = 0);
  ~WorkerPool();
  WorkerPool(WorkerPool&&) noexcept;
  WorkerPool& operator=(WorkerPool&&) noexcept;
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  [[nodiscard]] int threads() const { return threads_; }

  /// Calls work(begin, end) for disjoint ranges of at most `grain` indices (TBB may hand a worker
  /// several adjacent ones at once) covering [0, count), on the pool's threads and the calling
  /// one. An exception thrown by `work` is rethrown here once the running chunks have stopped;
  /// chunks not yet started are skipped.
  void for_ranges(int count, const std::function<void(int, int)>& work, int grain);

 private:
  struct Arena;  // the TBB task arena (absent under ThreadSanitizer)
  int threads_;
  std::unique_ptr<Arena> arena_;
};

/// The calling thread's pool of `threads` workers, made on its first use and kept for the
/// thread's life: what parallel_rows (parallel.h) runs on.
[[nodiscard]] WorkerPool& pool_for(int threads);

}  // namespace relight
