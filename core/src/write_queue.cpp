#include "relight/core/write_queue.h"

#include <sys/resource.h>
#include <unistd.h>

#include <oneapi/tbb/task_arena.h>

#include <algorithm>
#include <utility>

namespace relight {

WriteQueue::WriteQueue(std::size_t capacity)
    : capacity_(std::max<std::size_t>(capacity, 1)), worker_([this] { work(); }) {}

WriteQueue::~WriteQueue() {
  {
    const std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  worker_.join();
}

void WriteQueue::rethrow_failure() {
  if (!failure_) return;
  // Once: the caller ends the run with it; a second push would only repeat it.
  std::exception_ptr failure = std::exchange(failure_, nullptr);
  std::rethrow_exception(failure);
}

void WriteQueue::push(std::function<void()> job) {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [this] { return jobs_.size() < capacity_ || failure_; });
  rethrow_failure();
  jobs_.push_back(std::move(job));
  peak_depth_ = std::max(peak_depth_, jobs_.size());
  lock.unlock();
  changed_.notify_all();
}

void WriteQueue::drain() {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [this] { return (jobs_.empty() && !running_job_) || failure_; });
  rethrow_failure();
}

std::size_t WriteQueue::peak_depth() const {
  const std::lock_guard lock(mutex_);
  return peak_depth_;
}

void WriteQueue::work() {
#ifdef __linux__
  // Niced: the worker yields to the pipeline's own threads (at the same priority it competed with
  // the parallel loops and lavapipe's threads on two cores), yet keeps a share of a busy machine
  // (SCHED_IDLE would starve it - and, through the queue's back-pressure, the pipeline - while
  // anything else runs, e.g. a build). A full queue makes room: push() then waits.
  (void)setpriority(PRIO_PROCESS, static_cast<id_t>(::gettid()), 10);
#endif
  std::unique_lock lock(mutex_);
  while (true) {
    changed_.wait(lock, [this] { return !jobs_.empty() || stopping_; });
    if (jobs_.empty()) return;  // stopping, with nothing left to write
    std::function<void()> job = std::move(jobs_.front());
    jobs_.pop_front();
    running_job_ = true;
    lock.unlock();
    changed_.notify_all();  // room for a waiting push()
    std::exception_ptr failed;
    try {
      // In an arena of one: OpenCV's encoders run parallel loops on TBB, whose worker threads
      // would otherwise leave the pipeline's own loops to help here, at normal priority
      // (pipeline/replay_640x480's DIR stage took twice its time in such frames).
      tbb::task_arena alone(1);
      alone.execute([&job] { job(); });
    } catch (...) {
      failed = std::current_exception();
    }
    lock.lock();
    running_job_ = false;
    if (failed) {
      failure_ = failed;
      jobs_.clear();  // the rest would fail alike; atomic writes leave nothing half-written
    }
    changed_.notify_all();
  }
}

}  // namespace relight
