#pragma once
// The names of colour mapping's own frame-graph buffers (buffer_name.h); core/buffers.h has
// delta_L and color_mapped.
#include "relight/colormap/camera_look.h"
#include "relight/colormap/color_mapping.h"
#include "relight/core/buffer_name.h"

namespace relight::colormap {

inline constexpr BufferName<ColorMapping> kColorMapping{"color_mapping"};
/// The camera's blur, motion and noise of this frame, for the virtual layer (camera_look.h).
inline constexpr BufferName<CameraLook> kCameraLook{"camera_look"};

}  // namespace relight::colormap
