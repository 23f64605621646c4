#include "relight/capture/prefetch_source.h"

namespace relight::capture {

PrefetchSource::PrefetchSource(std::unique_ptr<FrameSource> source) : source_(std::move(source)) { read_ahead(); }

PrefetchSource::~PrefetchSource() { wait(); }

void PrefetchSource::read_ahead() {
  pending_ = std::async(std::launch::async, [source = source_.get()] { return source->next(); });
}

void PrefetchSource::wait() const {
  if (pending_.valid()) pending_.wait();
}

std::optional<RgbdFrame> PrefetchSource::next() {
  // After an error the caller may ask again (a source that skips or recovers): read in place.
  if (!pending_.valid()) read_ahead();
  std::optional<RgbdFrame> frame = pending_.get();  // rethrows the read's error
  if (frame) read_ahead();                          // nothing after the end of the stream
  return frame;
}

std::int64_t PrefetchSource::size_hint() const {
  wait();
  return source_->size_hint();
}

std::string PrefetchSource::describe() const {
  wait();
  return source_->describe();
}

}  // namespace relight::capture
