#include "relight/brdf/brdf_preview.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "relight/core/error.h"
#include "relight/core/parallel.h"
#include "relight/core/srgb.h"

namespace relight::brdf {
namespace {

/// Distinct colours for cluster ids 1.. (id 0, no material, stays black).
Rgb8 cluster_colour(std::uint16_t id) {
  static constexpr std::array<Rgb8, 8> kPalette{{{230, 25, 75},
                                                 {60, 180, 75},
                                                 {255, 225, 25},
                                                 {0, 130, 200},
                                                 {245, 130, 48},
                                                 {145, 30, 180},
                                                 {70, 240, 240},
                                                 {240, 50, 230}}};
  return id == 0 ? Rgb8{} : kPalette[(id - 1u) % kPalette.size()];
}

}  // namespace

ColorImage brdf_preview(const ColorImage& color, const Mask& highlights, const RadianceImage& kd,
                        const Materials& materials, const RadianceImage& rerender) {
  const int w = color.width(), h = color.height();
  for (const auto& [width, height] : {std::pair{highlights.width(), highlights.height()}, std::pair{kd.width(), kd.height()},
                                      std::pair{materials.ids.width(), materials.ids.height()},
                                      std::pair{rerender.width(), rerender.height()}})
    if (width != w || height != h) throw Error("brdf preview: the panels differ in size from the colour image");
  ColorImage out(5 * w, h);
  parallel_for_each_row(h, 0, [&](int row) {
    for (int col = 0; col < w; ++col) {
      out(row, col) = color(row, col);
      const std::uint8_t m = highlights(row, col) ? 255 : 0;
      out(row, w + col) = {m, m, m};
      out(row, 2 * w + col) = encode_srgb8(kd(row, col));
      out(row, 3 * w + col) = cluster_colour(materials.ids(row, col));
      out(row, 4 * w + col) = encode_srgb8(rerender(row, col));
    }
  });
  return out;
}

void BrdfPreviewStage::declare(StageBuilder& builder) {
  color_ = builder.read(buffers_.color);
  highlights_ = builder.read(buffers_.highlight_mask);
  kd_ = builder.read(buffers_.kd);
  materials_ = builder.read(buffers_.materials);
  positions_ = builder.read(buffers_.positions);
  normals_ = builder.read(buffers_.normals);
  lights_ = builder.read(buffers_.lights);
  frame_ = builder.read(buffers_.frame);
  preview_ = builder.write(output_name_);
}

void BrdfPreviewStage::run(StageContext& context) {
  if (wanted_ && !wanted_(context.frame_index())) {
    context.get(preview_) = ColorImage{};
    return;
  }
  const FrameInfo& frame = context.get(frame_);
  const ShadingLights lights =
      estimation_lights(context.get(lights_), frame.camera_to_world.value_or(Pose::Identity()));
  const Materials& materials = context.get(materials_);
  const RadianceImage rerender = render_materials(materials, context.get(positions_), context.get(normals_), lights);
  context.get(preview_) =
      brdf_preview(context.get(color_), context.get(highlights_), context.get(kd_), materials, rerender);
}

}  // namespace relight::brdf
