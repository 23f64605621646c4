#pragma once
// WriteQueue: output jobs (encoding and writing a file) run in order on one worker thread, so
// that a frame's pictures are written while the next frame is computed instead of on the
// pipeline's critical path.
//
// The queue is bounded: push() waits while `capacity` jobs are waiting (back-pressure: a slow
// disk slows the pipeline down instead of filling memory). A job that throws stops the queue:
// the jobs after it are dropped, and the error (the job's relight::Error, one line naming the
// file) is rethrown on the caller's thread by the next push() or by drain(), so a failed write
// still ends the run with that line. Every job writes its file atomically itself
// (atomic_file.h), so a dropped or failed job leaves no partial file.
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>

namespace relight {

class WriteQueue {
 public:
  /// capacity: the most jobs waiting at once (at least 1).
  explicit WriteQueue(std::size_t capacity);
  /// Waits for the queued jobs to finish; an error not yet rethrown is dropped (a destructor must
  /// not throw: call drain() to see it).
  ~WriteQueue();
  WriteQueue(const WriteQueue&) = delete;
  WriteQueue& operator=(const WriteQueue&) = delete;

  /// Queues `job`, waiting while the queue is full; rethrows a failed job's error first.
  void push(std::function<void()> job);
  /// Waits until every queued job has run; rethrows a failed job's error.
  void drain();
  /// The most jobs that were ever waiting at once (for reports and tests).
  [[nodiscard]] std::size_t peak_depth() const;

 private:
  void work();
  void rethrow_failure();  // with the lock held

  const std::size_t capacity_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<std::function<void()>> jobs_;
  bool running_job_ = false;
  bool stopping_ = false;
  std::exception_ptr failure_;
  std::size_t peak_depth_ = 0;
  std::thread worker_;  // last: started once the members above exist
};

}  // namespace relight
