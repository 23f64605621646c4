#pragma once
// Stage "as_rendered_composite": the differential composite without the camera's look (no blur,
// motion blur or noise on the virtual layer; colormap/camera_look.h), the "before" beside the
// composite's "after" on report.html's contact sheet. It is computed only for the frames the
// report shows (`wanted`); on the others it writes an empty image.
// Reads:  ColorImage "color", RadianceImage "L_rv", "L_r", CoverageImage "virtual_coverage",
//         GBuffer "dir_gbuffer", render::SpecularBackProjection "specular_back_projection",
//         colormap::ToneMap "tone_map".
// Writes: ColorImage "composite_as_rendered".
#include <cstdint>
#include <functional>
#include <string>

#include "relight/colormap/tone_map.h"
#include "relight/core/frame_graph.h"
#include "relight/render/dir/composite.h"
#include "relight/render/dir/gbuffer.h"

namespace relight::app {

inline constexpr BufferName<ColorImage> kCompositeAsRendered{"composite_as_rendered"};

class AsRenderedCompositeStage final : public Stage {
 public:
  AsRenderedCompositeStage(render::CompositeRule rule, std::function<bool(std::int64_t)> wanted)
      : rule_(rule), wanted_(std::move(wanted)) {}
  [[nodiscard]] std::string name() const override { return "as_rendered_composite"; }
  void declare(StageBuilder& builder) override;
  void run(StageContext& context) override;

 private:
  render::CompositeRule rule_;
  std::function<bool(std::int64_t)> wanted_;
  Read<ColorImage> color_;
  Read<RadianceImage> real_virtual_, real_;
  Read<render::CoverageImage> coverage_;
  Read<render::GBuffer> gbuffer_;
  Read<render::SpecularBackProjection> back_projection_;
  Read<colormap::ToneMap> tone_map_;
  Write<ColorImage> composite_;
};

}  // namespace relight::app
