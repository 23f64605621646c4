#include "relight/lights/probe_stream_stage.h"

namespace relight::lights {

void ProbeStreamStage::declare(StageBuilder& builder) {
  frame_ = builder.read(kSourceFrame);
  probe_ = builder.write(kProbe);
}

void ProbeStreamStage::run(StageContext& context) {
  const RadianceImage& probe = matcher_.probe_for(context.get(frame_).timestamp);
  RadianceImage& out = context.get(probe_);
  out = probe;
}

}  // namespace relight::lights
