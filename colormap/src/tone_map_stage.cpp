#include "relight/colormap/tone_map_stage.h"

namespace relight::colormap {

namespace {

/// The interval assumed where timestamps say nothing (the first frame, a repeated timestamp).
constexpr double kDefaultFrameInterval = 1.0 / 30.0;

}  // namespace

void ToneMapStage::declare(StageBuilder& builder) {
  if (options_.op == ToneOperator::Reinhard) {
    frame_ = builder.read(kFrame);
    previous_frame_ = builder.read_previous(kFrame);
    real_virtual_ = builder.read(kRealVirtualRadiance);
    previous_ = builder.read_previous(kToneMap);
  }
  tone_map_ = builder.write(kToneMap);
}

void ToneMapStage::run(StageContext& context) {
  if (options_.op == ToneOperator::Exposure) {
    last_ = adapt_tone_map(options_, {}, nullptr, 0.0);
  } else {
    const FrameInfo* previous_frame = context.get(previous_frame_);
    double interval = kDefaultFrameInterval;
    if (previous_frame) {
      const double dt = context.get(frame_).timestamp - previous_frame->timestamp;
      if (dt > 0.0) interval = dt;
    }
    last_ = adapt_tone_map(options_, scene_luminance(context.get(real_virtual_)), context.get(previous_), interval);
  }
  context.get(tone_map_) = last_;
}

}  // namespace relight::colormap
