#pragma once
// The names of colour mapping's own frame-graph buffers (buffer_name.h); core/buffers.h has
// delta_L and color_mapped.
#include "relight/colormap/color_mapping.h"
#include "relight/core/buffer_name.h"

namespace relight::colormap {

inline constexpr BufferName<ColorMapping> kColorMapping{"color_mapping"};

}  // namespace relight::colormap
