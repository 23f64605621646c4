#include "relight/core/parallel.h"
#include "relight/core/worker_pool.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <stdexcept>
#include <thread>
#include <vector>

namespace relight {
namespace {

TEST(ParallelRows, CoversEveryRowExactlyOnceForAnyThreadCountAndGrain) {
  for (int threads : {1, 2, 3, 8}) {
    for (int grain : {1, 7, 64}) {
      std::vector<std::atomic<int>> visits(301);
      parallel_rows(
          301, threads,
          [&](int begin, int end) {
            ASSERT_LT(begin, end);
            for (int row = begin; row < end; ++row) ++visits[static_cast<std::size_t>(row)];
          },
          grain);
      for (const auto& v : visits) ASSERT_EQ(v.load(), 1) << threads << " threads, grain " << grain;
    }
  }
}

TEST(ParallelRows, RethrowsTheWorkersExceptionOnTheCaller) {
  EXPECT_THROW(parallel_rows(
                   100, 4,
                   [](int begin, int) {
                     if (begin >= 50) throw std::runtime_error("row failed");
                   },
                   10),
               std::runtime_error);
}

TEST(ParallelRows, EmptyRangeDoesNothingAndForEachRowVisitsRows) {
  int calls = 0;
  parallel_rows(0, 4, [&](int, int) { ++calls; });
  EXPECT_EQ(calls, 0);
  std::vector<int> rows(10, 0);
  parallel_for_each_row(10, 2, [&](int row) { rows[static_cast<std::size_t>(row)] = row + 1; });
  for (int i = 0; i < 10; ++i) EXPECT_EQ(rows[static_cast<std::size_t>(i)], i + 1);
  EXPECT_GE(worker_count(0), 1);
  EXPECT_EQ(worker_count(3), 3);
}

TEST(WorkerPool, ReusedPoolCoversEveryIndexOnceAndSumsAgreeWithTheSerialLoop) {
  WorkerPool pool(3);
  EXPECT_EQ(pool.threads(), 3);
  for (int call = 0; call < 20; ++call) {
    const int count = 1000 + call * 37;
    std::vector<long> per_chunk_sums(static_cast<std::size_t>(count), 0);
    std::vector<std::atomic<int>> visits(static_cast<std::size_t>(count));
    pool.for_ranges(
        count,
        [&](int begin, int end) {
          for (int i = begin; i < end; ++i) {
            ++visits[static_cast<std::size_t>(i)];
            per_chunk_sums[static_cast<std::size_t>(i)] = static_cast<long>(i) * i;  // each index writes its own slot
          }
        },
        64);
    long total = 0;
    for (int i = 0; i < count; ++i) {
      ASSERT_EQ(visits[static_cast<std::size_t>(i)].load(), 1) << "call " << call << ", index " << i;
      total += per_chunk_sums[static_cast<std::size_t>(i)];
    }
    const long n = count - 1;
    EXPECT_EQ(total, n * (n + 1) * (2 * n + 1) / 6);
  }
}

TEST(WorkerPool, RethrowsTheFirstFailureAndStaysUsable) {
  WorkerPool pool(2);
  EXPECT_THROW(pool.for_ranges(
                   40,
                   [](int begin, int) {
                     if (begin == 30) throw std::runtime_error("chunk failed");
                   },
                   10),
               std::runtime_error);
  int calls = 0;
  pool.for_ranges(
      0, [&](int, int) { ++calls; }, 1);
  EXPECT_EQ(calls, 0);
  std::atomic<int> covered{0};
  pool.for_ranges(
      17, [&](int begin, int end) { covered += end - begin; }, 4);
  EXPECT_EQ(covered.load(), 17);
}

}  // namespace
}  // namespace relight

namespace relight {
namespace {

// parallel_rows runs on the calling thread's pools, one per thread count, made once: a pool
// (a TBB arena) per call piled up TBB's memory on a starved machine (parallel.cpp).
TEST(ParallelRows, EachCallingThreadKeepsOnePoolPerThreadCount) {
  WorkerPool& two = pool_for(2);
  EXPECT_EQ(&pool_for(2), &two);
  EXPECT_EQ(two.threads(), 2);
  EXPECT_NE(&pool_for(3), &two);
  EXPECT_EQ(pool_for(3).threads(), 3);
  const WorkerPool* other_thread = nullptr;
  std::thread([&] { other_thread = &pool_for(2); }).join();
  EXPECT_NE(other_thread, &two);
  // Still correct after a loop that threw.
  EXPECT_THROW(parallel_rows(
                   64, 2, [](int, int) { throw std::runtime_error("stop"); }, 8),
               std::runtime_error);
  std::vector<int> seen(64, 0);
  parallel_rows(
      64, 2,
      [&](int begin, int end) {
        for (int row = begin; row < end; ++row) ++seen[static_cast<std::size_t>(row)];
      },
      8);
  EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), 64);
}

}  // namespace
}  // namespace relight
