#include "relight/render/composite.h"

#include "relight/colormap/color_space.h"
#include "relight/core/error.h"

namespace relight::render {

ColorImage differential_composite(const ColorImage& camera, const RadianceImage& real_virtual,
                                  const RadianceImage& real, const CoverageImage& virtual_coverage,
                                  const colormap::ToneMap& tone_map) {
  const auto same_size = [&](const auto& image) {
    return image.width() == camera.width() && image.height() == camera.height();
  };
  if (!same_size(real_virtual) || !same_size(real) || !same_size(virtual_coverage))
    throw Error("differential composite: the camera image and the rendered images differ in size");
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

ColorImage tone_mapped_preview(const RadianceImage& radiance, const colormap::ToneMap& tone_map) {
  ColorImage out(radiance.width(), radiance.height());
  for (std::size_t i = 0; i < out.size(); ++i) out.pixels()[i] = colormap::encode_srgb8(colormap::tone_map(radiance.pixels()[i], tone_map));
  return out;
}

}  // namespace relight::render
