#pragma once
// Frame-graph stage of the colour-mapped differential composite (composite.h,
// mapped_differential_composite): the picture of `relight replay --colormap sample|stats`.
// Reads:  ColorImage "color" (camera), RadianceImage "delta_L" and ColorMapping "color_mapping"
//         (a colour-mapping stage, colormap_stages.h), RadianceImage "L_rv", "L_r" and CoverageImage
//         "virtual_coverage", GBuffer "dir_gbuffer" and SpecularBackProjection "specular_back_projection"
//         (the DIR stage, dir_stage.h); with `camera_look`, CameraLook
//         "camera_look" (camera_look_stage.h), whose artefacts go on the virtual layer.
// Writes: ColorImage "composite_mapped".
#include <string>

#include "relight/colormap/camera_look.h"
#include "relight/colormap/color_mapping.h"
#include "relight/core/frame_graph.h"
#include "relight/render/differential_images.h"
#include "relight/render/dir/composite.h"
#include "relight/render/dir/gbuffer.h"

namespace relight::render {

class MappedCompositeStage final : public Stage {
 public:
  explicit MappedCompositeStage(bool camera_look = false, CompositeRule rule = CompositeRule::Additive)
      : camera_look_(camera_look), rule_(rule) {}
  [[nodiscard]] std::string name() const override { return "mapped_composite"; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;

 private:
  Read<ColorImage> camera_;
  Read<RadianceImage> delta_, real_virtual_, real_;
  Read<CoverageImage> coverage_;
  Read<GBuffer> gbuffer_;
  Read<SpecularBackProjection> back_projection_;
  Read<colormap::ColorMapping> mapping_;
  bool camera_look_;
  CompositeRule rule_;
  Read<colormap::CameraLook> look_;
  Write<ColorImage> composite_;
};

}  // namespace relight::render
