#pragma once
// Frame-graph stage that pulls frames from a FrameSource.
// Writes: "color" (ColorImage), "depth" (DepthMap, metres), "frame" (FrameInfo; another name
// when a camera tracking stage writes "frame" from it: replay and live call it "source_frame").
// Signals end of stream when the source is exhausted. A frame without a capture time (FrameInfo::
// capture_time) gets the time it was delivered.
#include <memory>
#include <string>

#include "relight/capture/frame_source.h"
#include "relight/core/buffers.h"
#include "relight/core/frame_graph.h"

namespace relight::capture {

class SourceStage final : public Stage {
 public:
  explicit SourceStage(std::unique_ptr<FrameSource> source, BufferName<FrameInfo> frame_buffer = kFrame)
      : source_(std::move(source)), frame_buffer_(frame_buffer) {}
  [[nodiscard]] std::string name() const override { return "source"; }
  [[nodiscard]] bool has_side_effects() const override { return true; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;
  [[nodiscard]] const FrameSource& source() const { return *source_; }

 private:
  std::unique_ptr<FrameSource> source_;
  BufferName<FrameInfo> frame_buffer_;
  Write<ColorImage> color_;
  Write<DepthMap> depth_;
  Write<FrameInfo> frame_;
};

}  // namespace relight::capture
