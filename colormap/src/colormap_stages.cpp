// Frame-graph stages of the colour mapping (colormap_stages.h).
#include "relight/colormap/colormap_stages.h"

#include "relight/core/error.h"
#include "relight/vk/buffer.h"

namespace relight::colormap {

ColorMapInputs ColorMapInputs::declare(StageBuilder& builder, const ColorMapBuffers& buffers, bool camera) {
  ColorMapInputs inputs;
  inputs.real = builder.read(buffers.real);
  inputs.real_virtual = builder.read(buffers.real_virtual);
  if (camera) inputs.camera = builder.read(buffers.camera);
  if (buffers.tone_map) inputs.tone_map = builder.read(*buffers.tone_map);
  return inputs;
}

ToneMap ColorMapInputs::frame_tone_map(StageContext& context, const ToneMap& fixed) const {
  return tone_map ? context.get(*tone_map) : fixed;
}

StatisticsColorMapCpuStage::StatisticsColorMapCpuStage(ToneMap tm, ColorMapBuffers buffers)
    : tm_(tm), buffers_(std::move(buffers)) {}

void StatisticsColorMapCpuStage::declare(StageBuilder& builder) {
  inputs_ = ColorMapInputs::declare(builder, buffers_);
  delta_ = builder.write(buffers_.delta);
  mapping_ = builder.write(buffers_.mapping);
}

void StatisticsColorMapCpuStage::run(StageContext& context) {
  const ToneMap tm = inputs_.frame_tone_map(context, tm_);
  transfer_ = statistics_color_map(context.get(inputs_.real), context.get(inputs_.real_virtual),
                                   context.get(inputs_.camera), tm, context.get(delta_));
  context.get(mapping_) = ColorMapping::of_statistics(transfer_, tm);
}

StatisticsColorMapVkStage::StatisticsColorMapVkStage(vk::VulkanContext& context, ToneMap tm, ColorMapBuffers buffers)
    : mapper_(context), buffers_(std::move(buffers)) {
  mapper_.set_tone_map(tm);
}

void StatisticsColorMapVkStage::declare(StageBuilder& builder) {
  inputs_ = ColorMapInputs::declare(builder, buffers_);
  delta_ = builder.write(buffers_.delta);
  mapping_ = builder.write(buffers_.mapping);
}

void StatisticsColorMapVkStage::run(StageContext& context) {
  mapper_.set_tone_map(inputs_.frame_tone_map(context, mapper_.tone_map()));
  const RadianceImage& real_shape = context.shape_of(inputs_.real);
  const int width = real_shape.width(), height = real_shape.height();
  if (!real_shape.same_shape(context.shape_of(inputs_.real_virtual)) ||
      !real_shape.same_shape(context.shape_of(inputs_.camera))) {
    throw Error("colormap_statistics: L_r, L_rv and the camera image must have the same size");
  }
  auto& real = context.device_read<vk::VulkanBuffer>(inputs_.real);
  auto& real_virtual = context.device_read<vk::VulkanBuffer>(inputs_.real_virtual);
  auto& camera = context.device_read<vk::VulkanBuffer>(inputs_.camera);
  auto& delta = context.device_write<vk::VulkanBuffer>(delta_, [&](RadianceImage& out) { out.resize(width, height); });
  transfer_ = mapper_.run(real, real_virtual, camera, delta, width, height);
  context.get(mapping_) = ColorMapping::of_statistics(transfer_, mapper_.tone_map());
  if (const auto ms = mapper_.last_gpu_ms()) context.report_device_ms(*ms);
}

SampleColorMapStage::SampleColorMapStage(SampleMappingOptions options, ColorMapBuffers buffers)
    : mapper_(options), buffers_(std::move(buffers)) {}

void SampleColorMapStage::declare(StageBuilder& builder) {
  inputs_ = ColorMapInputs::declare(builder, buffers_);
  delta_ = builder.write(buffers_.delta);
  mapping_ = builder.write(buffers_.mapping);
}

void SampleColorMapStage::run(StageContext& context) {
  mapper_.set_tone_map(inputs_.frame_tone_map(context, mapper_.options().tone_map));
  const ColorMatrix& coefficients = mapper_.map(context.get(inputs_.real), context.get(inputs_.real_virtual),
                                                context.get(inputs_.camera), context.get(delta_));
  context.get(mapping_) = ColorMapping::of_matrix(coefficients, mapper_.options().tone_map);
}

IdentityColorMapStage::IdentityColorMapStage(ToneMap tm, ColorMapBuffers buffers)
    : tm_(tm), buffers_(std::move(buffers)) {}

void IdentityColorMapStage::declare(StageBuilder& builder) {
  inputs_ = ColorMapInputs::declare(builder, buffers_, false);
  delta_ = builder.write(buffers_.delta);
  mapping_ = builder.write(buffers_.mapping);
}

void IdentityColorMapStage::run(StageContext& context) {
  const ToneMap tm = inputs_.frame_tone_map(context, tm_);
  sample_delta(context.get(inputs_.real), context.get(inputs_.real_virtual), identity_color_matrix(), tm,
               context.get(delta_));
  context.get(mapping_) = ColorMapping::of_matrix(identity_color_matrix(), tm);
}

void ColorMapCompositeStage::declare(StageBuilder& builder) {
  camera_ = builder.read(buffers_.camera);
  delta_ = builder.read(buffers_.delta);
  mapped_ = builder.write(buffers_.mapped);
}

void ColorMapCompositeStage::run(StageContext& context) {
  context.get(mapped_) = composite(context.get(camera_), context.get(delta_));
}

std::unique_ptr<Stage> make_color_map_stage(ColorMapMethod method, Backend backend, vk::VulkanContext* context,
                                            const SampleMappingOptions& options, ColorMapBuffers buffers) {
  switch (method) {
    case ColorMapMethod::None: return std::make_unique<IdentityColorMapStage>(options.tone_map, std::move(buffers));
    case ColorMapMethod::Sample: return std::make_unique<SampleColorMapStage>(options, std::move(buffers));
    case ColorMapMethod::Statistics:
      if (backend == Backend::Cpu) {
        return std::make_unique<StatisticsColorMapCpuStage>(options.tone_map, std::move(buffers));
      }
      return std::make_unique<StatisticsColorMapVkStage>(require_vulkan_context(context, "make_color_map_stage"),
                                                         options.tone_map, buffers);
  }
  throw LogicError("make_color_map_stage: unknown method");
}

}  // namespace relight::colormap
