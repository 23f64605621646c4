#pragma once
// One RGB-D frame as every frame source delivers it, and the per-frame metadata that travels
// through the frame graph as the "frame" buffer.
#include <cstdint>
#include <optional>

#include "relight/core/camera.h"
#include "relight/core/image.h"
#include "relight/core/pose.h"

namespace relight {

struct FrameInfo {
  std::int64_t index = 0;           ///< position in the source (after any --frames range)
  Timestamp timestamp = 0.0;        ///< depth timestamp, seconds
  std::optional<Pose> camera_to_world;  ///< ground truth or tracked pose when known
  PinholeIntrinsics intrinsics;     ///< of the (registered) depth and colour images
  /// Host steady-clock seconds (std::chrono::steady_clock) at which the frame was captured: for
  /// a live device its timestamp mapped onto the host clock, else when the source delivered it;
  /// 0 until a source or SourceStage sets it. What capture-to-composite latency counts from.
  double capture_time = 0.0;
  static constexpr const char* type_name = "FrameInfo";
};

struct RgbdFrame {
  FrameInfo info;
  ColorImage color;
  DepthMap depth;  ///< registered to the colour image, metres
};

}  // namespace relight
