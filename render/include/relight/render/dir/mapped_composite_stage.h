#pragma once
// Frame-graph stage of the colour-mapped differential composite (composite.h,
// mapped_differential_composite): the picture of `relight replay --colormap sample|stats`.
// Reads:  ColorImage "color" (camera), RadianceImage "delta_L" and ColorMapping "color_mapping"
//         (a colour-mapping stage, colormap_stages.h), RadianceImage "L_rv" and CoverageImage
//         "virtual_coverage" (the DIR stage, dir_stage.h).
// Writes: ColorImage "composite_mapped".
#include <string>

#include "relight/colormap/color_mapping.h"
#include "relight/core/frame_graph.h"
#include "relight/render/differential_images.h"

namespace relight::render {

class MappedCompositeStage final : public Stage {
 public:
  [[nodiscard]] std::string name() const override { return "mapped_composite"; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;

 private:
  Read<ColorImage> camera_;
  Read<RadianceImage> delta_, real_virtual_;
  Read<CoverageImage> coverage_;
  Read<colormap::ColorMapping> mapping_;
  Write<ColorImage> composite_;
};

}  // namespace relight::render
