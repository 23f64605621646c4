#pragma once
// The names of reconstruct's own frame-graph buffers (buffer_name.h); core/buffers.h has the
// depth, position and normal maps.
#include "relight/core/buffer_name.h"
#include "relight/reconstruct/depth_warp_merge.h"

namespace relight::reconstruct {

inline constexpr BufferName<DepthWeightMap> kDepthWeight{"depth_weight"};  ///< method 2's merge weights

}  // namespace relight::reconstruct
