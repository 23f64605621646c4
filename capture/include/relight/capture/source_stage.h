#pragma once
// Frame-graph stage that pulls frames from a FrameSource.
// Writes: "color" (ColorImage), "depth" (DepthMap, metres), "frame" (FrameInfo).
// Signals end of stream when the source is exhausted.
#include <memory>

#include "relight/capture/frame_source.h"
#include "relight/core/frame_graph.h"

namespace relight {

class SourceStage final : public Stage {
 public:
  explicit SourceStage(std::unique_ptr<FrameSource> source) : source_(std::move(source)) {}
  [[nodiscard]] std::string name() const override { return "source"; }
  [[nodiscard]] bool has_side_effects() const override { return true; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;
  [[nodiscard]] const FrameSource& source() const { return *source_; }

 private:
  std::unique_ptr<FrameSource> source_;
  Write<ColorImage> color_;
  Write<DepthMap> depth_;
  Write<FrameInfo> frame_;
};

}  // namespace relight
