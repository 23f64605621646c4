#include "relight/capture/source_stage.h"
#include "relight/core/buffers.h"

#include <chrono>

namespace relight::capture {

void SourceStage::declare(StageBuilder& builder) {
  color_ = builder.write(kColor);
  depth_ = builder.write(kDepth);
  frame_ = builder.write(frame_buffer_);
}

void SourceStage::run(StageContext& context) {
  auto frame = source_->next();
  if (!frame) return context.end_of_stream();
  if (frame->info.capture_time == 0.0) {
    frame->info.capture_time =
        std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  }
  context.get(color_) = std::move(frame->color);
  context.get(depth_) = std::move(frame->depth);
  context.get(frame_) = std::move(frame->info);
}

}  // namespace relight::capture
