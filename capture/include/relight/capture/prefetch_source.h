#pragma once
// Reads the next frame on a worker thread while the pipeline works on the current one: a replay's
// frame is decoded from two PNGs (8-17 ms at 640x480, single-threaded), which otherwise sits at
// the head of every frame's critical path. One frame ahead, no more: memory stays bounded and
// the frames, their order and their errors are exactly the wrapped source's (an exception of a
// frame's read is rethrown by the next() that would have returned that frame).
// For sources that read files; live devices have their own queue (openni_source.h).
#include <future>
#include <memory>
#include <optional>
#include <string>

#include "relight/capture/frame_source.h"

namespace relight::capture {

class PrefetchSource final : public FrameSource {
 public:
  /// Starts reading the first frame at once.
  explicit PrefetchSource(std::unique_ptr<FrameSource> source);
  /// Waits for a read in flight (its result or error is dropped).
  ~PrefetchSource() override;
  PrefetchSource(const PrefetchSource&) = delete;
  PrefetchSource& operator=(const PrefetchSource&) = delete;

  [[nodiscard]] std::optional<RgbdFrame> next() override;
  /// Both wait for a read in flight first: the wrapped source is only ever used by one thread at
  /// a time.
  [[nodiscard]] std::int64_t size_hint() const override;
  [[nodiscard]] std::string describe() const override;

 private:
  void read_ahead();
  void wait() const;

  std::unique_ptr<FrameSource> source_;
  std::future<std::optional<RgbdFrame>> pending_;
};

}  // namespace relight::capture
