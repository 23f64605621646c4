#include "relight/render/dir/mapped_composite_stage.h"

#include "relight/render/dir/composite.h"

namespace relight::render {

void MappedCompositeStage::declare(StageBuilder& builder) {
  camera_ = builder.read<ColorImage>("color");
  delta_ = builder.read<RadianceImage>("delta_L");
  real_virtual_ = builder.read<RadianceImage>("L_rv");
  coverage_ = builder.read<CoverageImage>("virtual_coverage");
  mapping_ = builder.read<colormap::ColorMapping>("color_mapping");
  composite_ = builder.write<ColorImage>("composite_mapped");
}

void MappedCompositeStage::run(StageContext& context) {
  context.get(composite_) = mapped_differential_composite(context.get(camera_), context.get(delta_),
                                                          context.get(real_virtual_), context.get(coverage_),
                                                          context.get(mapping_));
}

}  // namespace relight::render
