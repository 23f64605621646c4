#pragma once
// Sink stage of `--view`: hands each frame's picture to the LiveView window, with a buffer beside
// it on request, and the frame, the pipeline's fps, the tracking state and the dropped frames
// written over it. While the view is paused the stage waits, so a replay pauses with it (a live
// device drops frames meanwhile, and the overlay counts them).
//
// Reads: the picture (ColorImage: the final composite, or "color" when nothing renders), the
//        side buffer when given (BufferPreviews' kinds), "camera_pose" (CameraPose),
//        "source_frame" (FrameInfo: the frame index).
#include <array>
#include <chrono>
#include <deque>
#include <functional>
#include <string>

#include "buffer_previews.h"
#include "live_view.h"
#include "option_values.h"
#include "relight/capture/camera_pose.h"
#include "relight/core/frame_graph.h"
#include "relight/core/rgbd_frame.h"

namespace relight::app {

/// The buffers --view-side can show beside the picture, and how each is drawn.
inline constexpr std::array<OptionValue<BufferPreviews::Kind>, 7> kViewSides{
    {{"color", BufferPreviews::Kind::Color},
     {"depth", BufferPreviews::Kind::Depth},
     {"depth_smoothed", BufferPreviews::Kind::Depth},
     {"depth_filtered", BufferPreviews::Kind::Depth},
     {"normals", BufferPreviews::Kind::Normals},
     {"composite", BufferPreviews::Kind::Color},
     {"virtual_coverage", BufferPreviews::Kind::Coverage}}};

class ViewStage final : public Stage {
 public:
  /// `side`: empty, or a buffer and its kind shown right of the picture.
  ViewStage(LiveView& view, std::string picture, std::string side = {},
            BufferPreviews::Kind side_kind = BufferPreviews::Kind::Color);
  [[nodiscard]] std::string name() const override { return "view"; }
  [[nodiscard]] bool has_side_effects() const override { return true; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;
  /// Live: the device's dropped-frame count, for the overlay.
  void count_dropped(std::function<std::int64_t()> dropped) { dropped_ = std::move(dropped); }

 private:
  LiveView& view_;
  std::string picture_name_;
  BufferPreviews side_;
  std::function<std::int64_t()> dropped_;
  std::deque<std::chrono::steady_clock::time_point> recent_;  ///< the last frames' times, for fps
  Read<ColorImage> picture_;
  Read<CameraPose> pose_;
  Read<FrameInfo> frame_;
};

}  // namespace relight::app
