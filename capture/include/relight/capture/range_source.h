#pragma once
// Frames [first, last) of a source that can only be read sequentially (an OpenNI2 .oni
// recording): the frames before `first` are read and dropped, indices count from 0 again.
#include <algorithm>
#include <cstddef>
#include <memory>
#include <optional>

#include "relight/capture/frame_source.h"

namespace relight::capture {

class RangeSource final : public FrameSource {
 public:
  RangeSource(std::unique_ptr<FrameSource> source, std::size_t first, std::optional<std::size_t> last)
      : source_(std::move(source)), first_(first), last_(last) {}
  std::optional<RgbdFrame> next() override {
    for (; position_ < first_; ++position_) {
      if (!source_->next()) return std::nullopt;
    }
    if (last_ && position_ >= *last_) return std::nullopt;
    auto frame = source_->next();
    if (frame) frame->info.index = static_cast<std::int64_t>(position_++ - first_);
    return frame;
  }
  std::int64_t size_hint() const override {
    const auto total = static_cast<std::size_t>(std::max<std::int64_t>(source_->size_hint(), 0));
    const std::size_t end = std::min(total, last_.value_or(total));
    return end > first_ ? static_cast<std::int64_t>(end - first_) : 0;
  }
  std::string describe() const override { return source_->describe(); }

 private:
  std::unique_ptr<FrameSource> source_;
  std::size_t first_;
  std::optional<std::size_t> last_;
  std::size_t position_ = 0;
};

}  // namespace relight::capture
