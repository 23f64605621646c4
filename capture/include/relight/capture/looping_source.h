#pragma once
// Plays a source `loops` times (soak tests, long benchmarks), reopening it through `open` for each
// pass: frame indices keep counting and timestamps keep increasing (one mean frame period between
// passes), so temporal stages see one long, continuous run.
#include <functional>
#include <memory>
#include <string>

#include "relight/capture/frame_source.h"

namespace relight::capture {

class LoopingSource final : public FrameSource {
 public:
  using Opener = std::function<std::unique_ptr<FrameSource>()>;
  LoopingSource(Opener open, int loops) : open_(std::move(open)), loops_(loops), source_(open_()) {}
  std::optional<RgbdFrame> next() override {
    for (;;) {
      if (auto frame = source_->next()) {
        if (loop_ == 0) last_timestamp_ = frame->info.timestamp;
        if (index_ == 0) first_timestamp_ = frame->info.timestamp;
        frame->info.index = index_++;
        frame->info.timestamp += loop_ * (last_timestamp_ - first_timestamp_ + kFramePeriod);
        return frame;
      }
      if (++loop_ >= loops_ || index_ == 0) return std::nullopt;
      source_ = open_();
    }
  }
  std::int64_t size_hint() const override { return source_->size_hint() * loops_; }
  std::string describe() const override {
    return source_->describe() + ", played " + std::to_string(loops_) + " times";
  }

 private:
  static constexpr double kFramePeriod = 1.0 / 30.0;
  Opener open_;
  int loops_;
  std::unique_ptr<FrameSource> source_;
  int loop_ = 0;
  std::int64_t index_ = 0;
  double first_timestamp_ = 0, last_timestamp_ = 0;
};

}  // namespace relight::capture
