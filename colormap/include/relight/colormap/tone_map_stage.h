#pragma once
// Stage "tone_map": this frame's tone-mapping operator, for every stage that maps radiance to the
// camera's range (the colour mappings, both composites).
//   reads  FrameInfo "frame" (and the previous frame's: the interval for the adaptation),
//          RadianceImage "L_rv" and the previous "tone_map" (Reinhard only: eqs. 1, 2, 4 of
//          Reinhard et al. 2002 over L_rv, adapted over time; adaptive_tone_map.h)
//   writes ToneMap "tone_map"
// With the Exposure operator it writes the fixed scale and reads nothing.
#include <string>

#include "relight/colormap/adaptive_tone_map.h"
#include "relight/colormap/buffers.h"
#include "relight/core/buffers.h"
#include "relight/core/frame_graph.h"

namespace relight::colormap {

class ToneMapStage final : public Stage {
 public:
  explicit ToneMapStage(ToneMapOptions options) : options_(options) {}
  [[nodiscard]] std::string name() const override { return "tone_map"; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;
  [[nodiscard]] const ToneMapOptions& options() const { return options_; }
  /// The last frame's operator (the report's "tone_map").
  [[nodiscard]] const ToneMap& last() const { return last_; }

 private:
  ToneMapOptions options_;
  ToneMap last_;
  Read<FrameInfo> frame_;
  ReadPrevious<FrameInfo> previous_frame_;
  Read<RadianceImage> real_virtual_;
  ReadPrevious<ToneMap> previous_;
  Write<ToneMap> tone_map_;
};

}  // namespace relight::colormap
