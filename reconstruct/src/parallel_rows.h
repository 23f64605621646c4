#pragma once
// Splits the rows of an image into contiguous bands, one per thread (the calling thread takes the
// last band). Per-pixel stages are memory-light and branchy, so plain std::thread bands beat a
// task pool at this size; below `min_rows` everything runs on the calling thread.
#include <algorithm>
#include <thread>
#include <vector>

namespace relight::detail {

inline int worker_count(int requested) {
  if (requested > 0) return requested;
  return static_cast<int>(std::clamp(std::thread::hardware_concurrency(), 1u, 8u));
}

/// Calls work(row_begin, row_end) over [0, rows) on `threads` threads (0 = all cores).
template <class Work>
void parallel_rows(int rows, int threads, Work&& work, int min_rows = 64) {
  const int count = std::min(worker_count(threads), std::max(1, rows / std::max(1, min_rows)));
  if (count <= 1) {
    work(0, rows);
    return;
  }
  std::vector<std::jthread> helpers;
  helpers.reserve(static_cast<std::size_t>(count - 1));
  const auto band = [&](int i) { return static_cast<int>(static_cast<long long>(rows) * i / count); };
  for (int i = 0; i < count - 1; ++i) helpers.emplace_back([&, i] { work(band(i), band(i + 1)); });
  work(band(count - 1), rows);
}

}  // namespace relight::detail
