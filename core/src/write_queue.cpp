#include "relight/core/write_queue.h"

#include <pthread.h>
#include <sched.h>

#include <oneapi/tbb/task_arena.h>

#include <algorithm>
#include <utility>

namespace relight {

WriteQueue::WriteQueue(std::size_t capacity)
    : capacity_(std::max<std::size_t>(capacity, 1)), worker_([this] { work(); }) {
#ifdef __linux__
  // The worker takes only CPU time the pipeline leaves idle: at normal priority it competed with
  // the parallel loops and lavapipe's threads on two cores and made the frame slower, not faster
  // (pipeline/replay_640x480: 719 ms serial, 880-930 ms with the writer at normal priority). A
  // full queue still makes room: push() then waits, and the idle core runs the worker.
  sched_param idle{};
  (void)pthread_setschedparam(worker_.native_handle(), SCHED_IDLE, &idle);
#endif
}

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
