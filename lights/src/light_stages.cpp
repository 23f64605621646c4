#include "relight/lights/light_stages.h"

#include "relight/core/error.h"

namespace relight::lights {

LightExtractionStage::LightExtractionStage(LightExtractionOptions options, LightExtractionBuffers buffers,
                                           vk::VulkanContext* context)
    : options_(std::move(options)), buffers_(std::move(buffers)), context_(context) {
  if (context_ && options_.method != LightMethod::Importance) {
    throw LogicError("LightExtractionStage: only importance sampling has a Vulkan version");
  }
}

LightExtractionStage::~LightExtractionStage() = default;

std::unique_ptr<Stage> make_light_extraction_stage(Backend backend, vk::VulkanContext* context,
                                                   LightExtractionOptions options, LightExtractionBuffers buffers) {
  return std::make_unique<LightExtractionStage>(std::move(options), std::move(buffers),
                                                context_for_backend(backend, context, "make_light_extraction_stage"));
}

void LightExtractionStage::declare(StageBuilder& builder) {
  probe_ = builder.read(buffers_.probe);
  lights_ = builder.write(buffers_.lights);
}

void LightExtractionStage::run(StageContext& context) {
  const RadianceImage& probe = context.get(probe_);
  if (!probe.same_shape(geometry_)) {
    geometry_ = ProbeGeometry(options_.calibration, probe.width(), probe.height());
    if (context_) vulkan_ = std::make_unique<ImportanceSamplerVk>(*context_, geometry_);
  }
  LightSet& lights = context.get(lights_);
  if (options_.method == LightMethod::MedianCut) {
    lights = median_cut(probe, geometry_, {options_.lights});
  } else if (vulkan_) {
    lights = vulkan_->run(probe, {options_.lights, options_.seed});
    if (const auto ms = vulkan_->last_gpu_ms()) context.report_device_ms(*ms);
  } else {
    lights = sample_importance(probe, geometry_, {options_.lights, options_.seed}, pyramid_);
  }
}

LightSet extract_lights(const RadianceImage& probe, const LightExtractionOptions& options) {
  const ProbeGeometry geometry(options.calibration, probe.width(), probe.height());
  if (options.method == LightMethod::MedianCut) return median_cut(probe, geometry, {options.lights});
  return sample_importance(probe, geometry, {options.lights, options.seed});
}

}  // namespace relight::lights
