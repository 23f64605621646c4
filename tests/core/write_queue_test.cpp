// WriteQueue (write_queue.h): jobs run in order on another thread, a full queue holds the caller
// back, a failed job's error reaches the caller once and drops the jobs queued after it, and the
// destructor waits for what is queued.
#include "relight/core/write_queue.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <future>
#include <vector>

#include "relight/core/error.h"

namespace relight {
namespace {

using namespace std::chrono_literals;

TEST(WriteQueue, RunsJobsInOrderOffTheCallersThread) {
  std::vector<int> order;
  std::vector<std::thread::id> threads;
  {
    WriteQueue queue(4);
    for (int i = 0; i < 20; ++i)
      queue.push([&, i] {
        order.push_back(i);
        threads.push_back(std::this_thread::get_id());
      });
    queue.drain();
    EXPECT_EQ(order.size(), 20u);
  }
  for (int i = 0; i < 20; ++i) EXPECT_EQ(order[static_cast<std::size_t>(i)], i);
  for (const auto& id : threads) EXPECT_NE(id, std::this_thread::get_id());
}

TEST(WriteQueue, AFullQueueHoldsTheCallerBack) {
  WriteQueue queue(1);
  std::promise<void> release;
  std::shared_future<void> released = release.get_future().share();
  std::atomic<int> started{0};
  queue.push([&] {
    ++started;
    released.wait();
  });
  while (started.load() == 0) std::this_thread::sleep_for(1ms);  // the worker holds job 1
  queue.push([] {});                                             // waits in the queue: now full
  auto third = std::async(std::launch::async, [&] { queue.push([] {}); });
  EXPECT_EQ(third.wait_for(50ms), std::future_status::timeout) << "push() must wait while the queue is full";
  release.set_value();
  EXPECT_EQ(third.wait_for(5s), std::future_status::ready);
  queue.drain();
  EXPECT_EQ(queue.peak_depth(), 1u);
}

TEST(WriteQueue, AFailedJobsErrorReachesTheCallerOnceAndDropsTheRest) {
  WriteQueue queue(8);
  std::atomic<int> ran{0};
  std::promise<void> release;
  std::shared_future<void> released = release.get_future().share();
  queue.push([&] {
    released.wait();
    throw Error("cannot write out/frames/000003_composite.png: No space left on device");
  });
  queue.push([&] { ++ran; });  // queued behind the failing job
  release.set_value();
  try {
    queue.drain();
    FAIL() << "drain() must rethrow the job's error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "cannot write out/frames/000003_composite.png: No space left on device");
  }
  EXPECT_EQ(ran.load(), 0) << "jobs after a failure are dropped";
  EXPECT_NO_THROW(queue.drain()) << "reported once";
  queue.push([&] { ++ran; });
  queue.drain();
  EXPECT_EQ(ran.load(), 1);
}

TEST(WriteQueue, TheDestructorWaitsForQueuedJobs) {
  std::atomic<int> ran{0};
  {
    WriteQueue queue(16);
    for (int i = 0; i < 10; ++i)
      queue.push([&] {
        std::this_thread::sleep_for(2ms);
        ++ran;
      });
  }
  EXPECT_EQ(ran.load(), 10);
}

}  // namespace
}  // namespace relight
