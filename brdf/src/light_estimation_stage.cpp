#include "relight/brdf/light_estimation_stage.h"

namespace relight::brdf {

void LightEstimationStage::declare(StageBuilder& builder) {
  color_ = builder.read(kColorDiffuse);
  highlights_ = builder.read(kHighlightMask);
  positions_ = builder.read(kPositions);
  normals_ = builder.read(kNormals);
  frame_ = builder.read(kFrame);
  probe_ = builder.write(kProbe);
}

void LightEstimationStage::run(StageContext& context) {
  const FrameInfo& frame = context.get(frame_);
  estimator_.add_frame(context.get(color_), &context.get(highlights_), context.get(positions_), context.get(normals_),
                       frame.intrinsics, frame.camera_to_world.value_or(Pose::Identity()));
  context.get(probe_) = estimator_.environment_map();
}

}  // namespace relight::brdf
