// The CPU reference of the depth box filter (definition in depth_box_filter.h). Deliberately
// plain: the Vulkan shader is checked against this, so clarity beats speed here.
#include <algorithm>

#include "relight/core/error.h"
#include "relight/reconstruct/depth_box_filter.h"

namespace relight::reconstruct {

namespace {

// Mean of the valid depths in the 3x3 window around a valid centre, summed row-major like the
// shader so both round identically.
float window_mean(const DepthMap& depth, int row, int col) {
  float sum = 0.f;
  int count = 0;
  for (int r = std::max(row - 1, 0); r <= std::min(row + 1, depth.height() - 1); ++r) {
    for (int c = std::max(col - 1, 0); c <= std::min(col + 1, depth.width() - 1); ++c) {
      const float d = depth(r, c);
      if (is_valid_depth(d)) {
        sum += d;
        ++count;
      }
    }
  }
  return sum / static_cast<float>(count);
}

}  // namespace

void depth_box_filter(const DepthMap& depth, DepthMap& smoothed) {
  if (&depth == &smoothed) throw LogicError("depth_box_filter: output must not alias the input");
  smoothed.resize(depth.width(), depth.height());
  for (int row = 0; row < depth.height(); ++row) {
    for (int col = 0; col < depth.width(); ++col) {
      smoothed(row, col) = is_valid_depth(depth(row, col)) ? window_mean(depth, row, col) : 0.f;
    }
  }
}

DepthMap depth_box_filter(const DepthMap& depth) {
  DepthMap smoothed;
  depth_box_filter(depth, smoothed);
  return smoothed;
}

void DepthBoxFilterCpuStage::declare(StageBuilder& builder) {
  input_ = builder.read(buffers_.input);
  output_ = builder.write(buffers_.output);
}

void DepthBoxFilterCpuStage::run(StageContext& context) {
  depth_box_filter(context.get(input_), context.get(output_));
}

}  // namespace relight::reconstruct
