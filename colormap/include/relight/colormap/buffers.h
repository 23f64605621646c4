#pragma once
// The names of colour mapping's own frame-graph buffers (buffer_name.h); core/buffers.h has
// delta_L and color_mapped.
#include "relight/colormap/camera_look.h"
#include "relight/colormap/color_mapping.h"
#include "relight/colormap/tone_map.h"
#include "relight/core/buffer_name.h"

namespace relight::colormap {

inline constexpr BufferName<ColorMapping> kColorMapping{"color_mapping"};
/// This frame's tone-mapping operator (tone_map_stage.h).
inline constexpr BufferName<ToneMap> kToneMap{"tone_map"};
/// The camera's blur, motion and noise of this frame, for the virtual layer (camera_look.h).
inline constexpr BufferName<CameraLook> kCameraLook{"camera_look"};

}  // namespace relight::colormap
