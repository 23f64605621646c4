#include "relight/render/dir/composite.h"

#include "relight/colormap/color_space.h"
#include "relight/core/error.h"

namespace relight::render {

namespace {

void require_camera_size(const ColorImage& camera, std::initializer_list<const Image<Float3>*> radiance,
                         const CoverageImage& coverage) {
  bool same = camera.same_shape(coverage);
  for (const auto* image : radiance) same = same && camera.same_shape(*image);
  if (!same) throw Error("differential composite: the camera image and the rendered images differ in size");
}

}  // namespace

ColorImage differential_composite(const ColorImage& camera, const RadianceImage& real_virtual,
                                  const RadianceImage& real, const CoverageImage& virtual_coverage,
                                  const colormap::ToneMap& tone_map) {
  require_camera_size(camera, {&real_virtual, &real}, virtual_coverage);
  ColorImage out(camera.width(), camera.height());
  for (std::size_t i = 0; i < out.size(); ++i) {
    const Float3 with = colormap::tone_map(real_virtual.pixels()[i], tone_map);
    const Float3 without = colormap::tone_map(real.pixels()[i], tone_map);
    const Float3 background = colormap::decode_srgb8(camera.pixels()[i]) + (with - without);
    const float c = virtual_coverage.pixels()[i];
    out.pixels()[i] = colormap::encode_srgb8(c * with + (1.f - c) * background);
  }
  return out;
}

ColorImage mapped_differential_composite(const ColorImage& camera, const RadianceImage& delta,
                                         const RadianceImage& real_virtual, const CoverageImage& virtual_coverage,
                                         const colormap::ColorMapping& mapping) {
  require_camera_size(camera, {&delta, &real_virtual}, virtual_coverage);
  ColorImage out(camera.width(), camera.height());
  for (std::size_t i = 0; i < out.size(); ++i) {
    const Float3& d = delta.pixels()[i];
    const float c = virtual_coverage.pixels()[i];
    if (c == 0.f && d == Float3{}) {
      out.pixels()[i] = camera.pixels()[i];
      continue;
    }
    Float3 mapped = colormap::decode_srgb8(camera.pixels()[i]) + d;
    if (c > 0.f) mapped = c * mapping(real_virtual.pixels()[i]) + (1.f - c) * mapped;
    out.pixels()[i] = colormap::encode_srgb8(mapped);
  }
  return out;
}

ColorImage tone_mapped_preview(const RadianceImage& radiance, const colormap::ToneMap& tone_map) {
  ColorImage out(radiance.width(), radiance.height());
  for (std::size_t i = 0; i < out.size(); ++i) out.pixels()[i] = colormap::encode_srgb8(colormap::tone_map(radiance.pixels()[i], tone_map));
  return out;
}

}  // namespace relight::render
