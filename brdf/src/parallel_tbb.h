#pragma once
// Row- and cluster-parallel loops of relight_brdf on TBB. Unlike parallel_rows() (core), which
// starts and joins helper threads on every call, TBB keeps its workers alive and runs any range
// nobody has taken on the calling thread, so a stage never waits for a helper to be scheduled
// (on a loaded machine that wait cost more than the short per-frame loops themselves). The
// result must not depend on the schedule: each range writes only its own outputs. Private to
// relight_brdf.
#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>

#include "relight/core/parallel.h"

namespace relight::brdf::detail {

/// Calls work(begin, end) for disjoint ranges of at least `grain` covering [0, count), on up to
/// `threads` threads (0: TBB's default; 1: the calling thread alone).
template <class Work>
void parallel_ranges(int count, int threads, int grain, Work&& work) {
  if (count <= 0) return;
  if (threads == 1 || count <= grain) {
    work(0, count);
    return;
  }
  auto run = [&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, count, grain),
                      [&](const tbb::blocked_range<int>& range) { work(range.begin(), range.end()); });
  };
  if (threads <= 0) {
    run();
    return;
  }
  tbb::task_arena arena(worker_count(threads));
  arena.execute(run);
}

/// parallel_ranges calling body(row) once per row.
template <class Body>
void parallel_each_row(int rows, int threads, Body&& body, int grain = 4) {
  parallel_ranges(rows, threads, grain, [&](int begin, int end) {
    for (int row = begin; row < end; ++row) body(row);
  });
}

}  // namespace relight::brdf::detail
