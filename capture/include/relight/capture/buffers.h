#pragma once
// The names of capture's own frame-graph buffers (buffer_name.h); core/buffers.h has the colour,
// depth and frame buffers the source and the tracker write.
#include "relight/capture/camera_pose.h"
#include "relight/core/buffer_name.h"

namespace relight::capture {

inline constexpr BufferName<CameraPose> kCameraPose{"camera_pose"};  ///< the tracked camera (camera_tracking_stage.h)
inline constexpr BufferName<CameraPose> kMarkerPose{"marker_pose"};  ///< from the AprilTags (marker_pose.h)

}  // namespace relight::capture
