#include "relight/core/parallel.h"

#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
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

}  // namespace
}  // namespace relight
