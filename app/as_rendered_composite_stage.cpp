#include "as_rendered_composite_stage.h"

#include "relight/colormap/buffers.h"
#include "relight/core/buffers.h"
#include "relight/render/buffers.h"

namespace relight::app {

void AsRenderedCompositeStage::declare(StageBuilder& builder) {
  color_ = builder.read(kColor);
  real_virtual_ = builder.read(kRealVirtualRadiance);
  real_ = builder.read(kRealRadiance);
  coverage_ = builder.read(render::kVirtualCoverage);
  gbuffer_ = builder.read(render::kDirGBuffer);
  back_projection_ = builder.read(render::kSpecularBackProjection);
  tone_map_ = builder.read(colormap::kToneMap);
  composite_ = builder.write(kCompositeAsRendered);
}

void AsRenderedCompositeStage::run(StageContext& context) {
  ColorImage& out = context.get(composite_);
  if (!wanted_(context.frame_index())) {
    out = ColorImage{};
    return;
  }
  out = render::differential_composite(
      context.get(color_), context.get(real_virtual_), context.get(real_), context.get(coverage_),
      context.get(tone_map_), {rule_, nullptr, &context.get(gbuffer_).virtual_surface, &context.get(back_projection_)});
}

}  // namespace relight::app
