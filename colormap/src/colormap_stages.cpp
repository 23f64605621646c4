// Frame-graph stages of the colour mapping (colormap_stages.h).
#include "relight/colormap/colormap_stages.h"

#include "relight/core/error.h"
#include "relight/vk/buffer.h"

namespace relight::colormap {

namespace {

struct Inputs {
  Read<RadianceImage> real, real_virtual;
  Read<ColorImage> camera;
};

Inputs declare_inputs(StageBuilder& builder, const ColorMapBuffers& buffers) {
  return {builder.read(buffers.real), builder.read(buffers.real_virtual), builder.read(buffers.camera)};
}

}  // namespace

StatisticsColorMapCpuStage::StatisticsColorMapCpuStage(ToneMap tm, ColorMapBuffers buffers)
    : tm_(tm), buffers_(std::move(buffers)) {}

void StatisticsColorMapCpuStage::declare(StageBuilder& builder) {
  const Inputs inputs = declare_inputs(builder, buffers_);
  real_ = inputs.real;
  real_virtual_ = inputs.real_virtual;
  camera_ = inputs.camera;
  delta_ = builder.write(buffers_.delta);
  mapping_ = builder.write(buffers_.mapping);
}

void StatisticsColorMapCpuStage::run(StageContext& context) {
  transfer_ = statistics_color_map(context.get(real_), context.get(real_virtual_), context.get(camera_), tm_,
                                   context.get(delta_));
  context.get(mapping_) = ColorMapping::of_statistics(transfer_, tm_);
}

StatisticsColorMapVkStage::StatisticsColorMapVkStage(vk::VulkanContext& context, ToneMap tm, ColorMapBuffers buffers)
    : mapper_(context), buffers_(std::move(buffers)) {
  mapper_.set_tone_map(tm);
}

void StatisticsColorMapVkStage::declare(StageBuilder& builder) {
  const Inputs inputs = declare_inputs(builder, buffers_);
  real_ = inputs.real;
  real_virtual_ = inputs.real_virtual;
  camera_ = inputs.camera;
  delta_ = builder.write(buffers_.delta);
  mapping_ = builder.write(buffers_.mapping);
}

void StatisticsColorMapVkStage::run(StageContext& context) {
  const RadianceImage& real_shape = context.shape_of(real_);
  const int width = real_shape.width(), height = real_shape.height();
  if (!real_shape.same_shape(context.shape_of(real_virtual_)) || !real_shape.same_shape(context.shape_of(camera_))) {
    throw Error("colormap_statistics: L_r, L_rv and the camera image must have the same size");
  }
  auto& real = context.device_read<vk::VulkanBuffer>(real_);
  auto& real_virtual = context.device_read<vk::VulkanBuffer>(real_virtual_);
  auto& camera = context.device_read<vk::VulkanBuffer>(camera_);
  auto& delta = context.device_write<vk::VulkanBuffer>(delta_, [&](RadianceImage& out) { out.resize(width, height); });
  transfer_ = mapper_.run(real, real_virtual, camera, delta, width, height);
  context.get(mapping_) = ColorMapping::of_statistics(transfer_, mapper_.tone_map());
  if (const auto ms = mapper_.last_gpu_ms()) context.report_device_ms(*ms);
}

SampleColorMapStage::SampleColorMapStage(SampleMappingOptions options, ColorMapBuffers buffers)
    : mapper_(options), buffers_(std::move(buffers)) {}

void SampleColorMapStage::declare(StageBuilder& builder) {
  const Inputs inputs = declare_inputs(builder, buffers_);
  real_ = inputs.real;
  real_virtual_ = inputs.real_virtual;
  camera_ = inputs.camera;
  delta_ = builder.write(buffers_.delta);
  mapping_ = builder.write(buffers_.mapping);
}

void SampleColorMapStage::run(StageContext& context) {
  const ColorMatrix& coefficients =
      mapper_.map(context.get(real_), context.get(real_virtual_), context.get(camera_), context.get(delta_));
  context.get(mapping_) = ColorMapping::of_matrix(coefficients, mapper_.options().tone_map);
}

IdentityColorMapStage::IdentityColorMapStage(ToneMap tm, ColorMapBuffers buffers)
    : tm_(tm), buffers_(std::move(buffers)) {}

void IdentityColorMapStage::declare(StageBuilder& builder) {
  real_ = builder.read(buffers_.real);
  real_virtual_ = builder.read(buffers_.real_virtual);
  delta_ = builder.write(buffers_.delta);
  mapping_ = builder.write(buffers_.mapping);
}

void IdentityColorMapStage::run(StageContext& context) {
  sample_delta(context.get(real_), context.get(real_virtual_), identity_color_matrix(), tm_, context.get(delta_));
  context.get(mapping_) = ColorMapping::of_matrix(identity_color_matrix(), tm_);
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
