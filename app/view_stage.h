#pragma once
// Sink stage of `--view`: hands each frame's picture to the LiveView window, with a buffer beside
// it on request, and the frame, the pipeline's fps, the tracking state and the dropped frames
// written over it. While the view is paused the stage waits, so a replay pauses with it (a live
// device drops frames meanwhile, and the overlay counts them).
//
// Reads: the picture (ColorImage: the final composite, or "color" when nothing renders), the
//        side buffer when given (a PreviewBuffer, drawn by its type), "camera_pose" (CameraPose),
//        "source_frame" (FrameInfo: the frame index).
#include <array>
#include <chrono>
#include <deque>
#include <functional>
#include <optional>
#include <string>

#include "buffer_previews.h"
#include "live_view.h"
#include "option_values.h"
#include "relight/capture/buffers.h"
#include "relight/capture/camera_pose.h"
#include "relight/core/buffers.h"
#include "relight/core/frame_graph.h"
#include "relight/core/rgbd_frame.h"
#include "relight/render/buffers.h"

namespace relight::app {

/// The buffers --view-side can show beside the picture, and how each is drawn.
inline constexpr std::array<NamedValue<PreviewBuffer>, 7> kViewSides{
    {{kColor.name(), kColor},
     {kDepth.name(), kDepth},
     {kDepthSmoothed.name(), kDepthSmoothed},
     {kDepthFiltered.name(), kDepthFiltered},
     {kNormals.name(), kNormals},
     {kComposite.name(), kComposite},
     {render::kVirtualCoverage.name(), render::kVirtualCoverage}}};

class ViewStage final : public Stage {
 public:
  /// `side`: empty, or a buffer and its kind shown right of the picture.
  ViewStage(LiveView& view, BufferName<ColorImage> picture, std::optional<PreviewBuffer> side = std::nullopt);
  [[nodiscard]] std::string name() const override { return "view"; }
  [[nodiscard]] bool has_side_effects() const override { return true; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;
  /// Live: the device's dropped-frame count, for the overlay.
  void count_dropped(std::function<std::int64_t()> dropped) { dropped_ = std::move(dropped); }

 private:
  LiveView& view_;
  BufferName<ColorImage> picture_name_;
  BufferPreviews side_;
  std::function<std::int64_t()> dropped_;
  std::deque<std::chrono::steady_clock::time_point> recent_;  ///< the last frames' times, for fps
  Read<ColorImage> picture_;
  Read<capture::CameraPose> pose_;
  Read<FrameInfo> frame_;
};

}  // namespace relight::app
