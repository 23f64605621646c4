#pragma once
// Frame-graph stage that delivers the light probe of each RGB-D frame.
//
//   reads  FrameInfo     "source_frame"  (its timestamp)
//   writes RadianceImage "probe"         (linear radiance, the frame's probe: probe_stream.h)
// LightExtractionStage and LightSmoothingStage (light_stages.h, light_smoothing.h) turn it into
// the frame's lights.
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "relight/core/buffers.h"
#include "relight/core/frame_graph.h"
#include "relight/lights/probe_stream.h"

namespace relight::lights {

class ProbeStreamStage final : public Stage {
 public:
  ProbeStreamStage(std::unique_ptr<ProbeStream> stream, ProbeMatchOptions options = {},
                   std::ostream& warnings = std::cerr)
      : matcher_(std::move(stream), options, warnings) {}
  [[nodiscard]] std::string name() const override { return "probe_stream"; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;
  [[nodiscard]] const ProbeMatcher& matcher() const { return matcher_; }
  [[nodiscard]] nlohmann::ordered_json summary() const { return matcher_.summary(); }

 private:
  ProbeMatcher matcher_;
  Read<FrameInfo> frame_;
  Write<RadianceImage> probe_;
};

}  // namespace relight::lights
