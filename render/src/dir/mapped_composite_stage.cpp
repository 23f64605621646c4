#include "relight/render/dir/mapped_composite_stage.h"

#include "relight/colormap/buffers.h"
#include "relight/core/buffers.h"
#include "relight/render/buffers.h"
#include "relight/render/dir/composite.h"

namespace relight::render {

void MappedCompositeStage::declare(StageBuilder& builder) {
  camera_ = builder.read(kColor);
  delta_ = builder.read(kDeltaRadiance);
  real_virtual_ = builder.read(kRealVirtualRadiance);
  real_ = builder.read(kRealRadiance);
  coverage_ = builder.read(kVirtualCoverage);
  mapping_ = builder.read(colormap::kColorMapping);
  gbuffer_ = builder.read(kDirGBuffer);
  back_projection_ = builder.read(kSpecularBackProjection);
  if (camera_look_) look_ = builder.read(colormap::kCameraLook);
  composite_ = builder.write(kCompositeMapped);
}

void MappedCompositeStage::run(StageContext& context) {
  context.get(composite_) =
      mapped_differential_composite(context.get(camera_), context.get(delta_), context.get(real_virtual_),
                                    context.get(real_), context.get(coverage_), context.get(mapping_),
                                    {rule_, camera_look_ ? &context.get(look_) : nullptr,
                                     &context.get(gbuffer_).virtual_surface, &context.get(back_projection_)});
}

}  // namespace relight::render
