#pragma once
// Row-parallel loops for per-pixel CPU stages and the synthetic renderer, on a WorkerPool (TBB's
// thread pool, worker_pool.h):
// chunks of `grain` rows are scheduled by work stealing, so uneven rows (a ray caster's sky
// against its table) balance across threads. The result must not depend on the schedule: each
// row (or chunk) writes only its own outputs.
#include <functional>

namespace relight {

/// Threads to use for `requested` (0 = all hardware threads, at most 8; at least 1).
[[nodiscard]] int worker_count(int requested);

/// Calls work(row_begin, row_end) for disjoint ranges covering [0, rows), on up to `threads`
/// threads (0 = worker_count(0)); the calling thread works too. With one thread or fewer than
/// two chunks it all runs on the calling thread. An exception thrown by `work` is rethrown here
/// once the other chunks have stopped (chunks not yet started are cancelled).
void parallel_rows(int rows, int threads, const std::function<void(int, int)>& work, int grain = 16);

/// parallel_rows calling body(row) once per row.
template <class Body>
void parallel_for_each_row(int rows, int threads, Body&& body, int grain = 4) {
  parallel_rows(
      rows, threads,
      [&](int begin, int end) {
        for (int row = begin; row < end; ++row) body(row);
      },
      grain);
}

}  // namespace relight
